//! A technique's quality knobs as data: name, help, range, default and the values a sweep
//! measures, declared once in the technique's module. The command line (`crate::cli`), the
//! benchmark's sweep (`crate::sweep::plan`) and the technique's own constructor all read them
//! from there; a constructor reads its values by name through [`Knobs`].

/// A knob's value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KnobValue {
    /// A number.
    Number(f32),
    /// The index of one of a choice knob's options.
    Choice(usize),
}

impl KnobValue {
    /// The value as a number (a choice's index).
    pub fn number(self) -> f32 {
        match self {
            KnobValue::Number(v) => v,
            KnobValue::Choice(i) => i as f32,
        }
    }
}

/// The values a knob takes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KnobRange {
    /// A number in `min..=max` (`max` may be infinite); `sweep` lists the values worth
    /// measuring.
    Number {
        /// Smallest value.
        min: f32,
        /// Largest value.
        max: f32,
        /// Values a sweep should measure.
        sweep: &'static [f32],
        /// Whether only whole numbers are valid (a count).
        whole: bool,
    },
    /// One of the named options.
    Choice(&'static [&'static str]),
}

/// What a knob does, for a sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KnobRole {
    /// Trades time for error: a sweep measures its values.
    Quality,
    /// Changes the scene the technique renders (a light's size, an artistic gain): a sweep holds
    /// it at its default, which is what the reference path tracer renders.
    Scene,
}

/// A quality knob of a technique.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knob {
    /// Name (also the command-line flag without `--`).
    pub name: &'static str,
    /// What it does.
    pub help: &'static str,
    /// Valid values.
    pub range: KnobRange,
    /// The default.
    pub default: KnobValue,
    /// Whether it trades time for error, or changes what is rendered.
    pub role: KnobRole,
}

/// A number knob that trades time for error.
pub const fn number(
    name: &'static str,
    help: &'static str,
    min: f32,
    max: f32,
    default: f32,
    sweep: &'static [f32],
) -> Knob {
    Knob {
        name,
        help,
        range: KnobRange::Number { min, max, sweep, whole: false },
        default: KnobValue::Number(default),
        role: KnobRole::Quality,
    }
}

/// `knob` (a [`number`]) taking whole numbers only: a count.
pub const fn whole(knob: Knob) -> Knob {
    match knob.range {
        KnobRange::Number { min, max, sweep, .. } => {
            Knob { range: KnobRange::Number { min, max, sweep, whole: true }, ..knob }
        }
        KnobRange::Choice(_) => knob,
    }
}

/// A choice knob that trades time for error; `default` indexes `options`.
pub const fn choice(
    name: &'static str,
    help: &'static str,
    options: &'static [&'static str],
    default: usize,
) -> Knob {
    Knob {
        name,
        help,
        range: KnobRange::Choice(options),
        default: KnobValue::Choice(default),
        role: KnobRole::Quality,
    }
}

/// `knob` as one that changes what is rendered (a light's size, an artistic gain): a sweep
/// holds it at its default.
pub const fn scene(knob: Knob) -> Knob {
    Knob { role: KnobRole::Scene, ..knob }
}

/// The upper end of an open range.
pub const UNBOUNDED: f32 = f32::INFINITY;

impl Knob {
    /// Whether `value` is valid for this knob.
    pub fn check(&self, value: KnobValue) -> Result<(), String> {
        match (self.range, value) {
            (KnobRange::Number { min, max, whole, .. }, KnobValue::Number(v)) => {
                if whole && v.fract() != 0.0 {
                    Err(format!("{} must be a whole number in {min}..={max}, not {v}", self.name))
                } else if v.is_finite() && v >= min && v <= max {
                    Ok(())
                } else {
                    Err(format!("{} must be a number in {min}..={max}, not {v}", self.name))
                }
            }
            (KnobRange::Choice(options), KnobValue::Choice(i)) if i < options.len() => Ok(()),
            (KnobRange::Choice(options), _) => {
                Err(format!("{} must be one of {}", self.name, options.join(", ")))
            }
            (KnobRange::Number { .. }, KnobValue::Choice(_)) => Err(format!("{} takes a number", self.name)),
        }
    }

    /// The default as the command line spells it (`0.6`, `half`).
    pub fn default_text(&self) -> String {
        match (self.range, self.default) {
            (KnobRange::Choice(options), KnobValue::Choice(i)) => options[i].to_string(),
            (_, v) => v.number().to_string(),
        }
    }

    /// The value the command line's text `s` gives this knob, or what is wrong with it.
    pub fn parse(&self, s: &str) -> Result<KnobValue, String> {
        let value = match self.range {
            KnobRange::Choice(options) => {
                let i = options
                    .iter()
                    .position(|o| *o == s)
                    .ok_or_else(|| format!("'{s}' is not one of {}", options.join(", ")))?;
                KnobValue::Choice(i)
            }
            KnobRange::Number { .. } => {
                KnobValue::Number(s.trim().parse::<f32>().map_err(|_| format!("'{s}' is not a number"))?)
            }
        };
        Ok(value)
    }
}

/// The knob values a technique is built from, read by name (never by position: a module may
/// reorder its knobs freely).
#[derive(Debug, Clone)]
pub struct Knobs {
    technique: String,
    knobs: &'static [Knob],
    values: Vec<KnobValue>,
}

impl Knobs {
    /// Every knob of `knobs` at its default, for the technique `technique` (named in errors).
    pub fn defaults(technique: String, knobs: &'static [Knob]) -> Knobs {
        Knobs { technique, values: knobs.iter().map(|k| k.default).collect(), knobs }
    }

    /// Sets the knob `name` to `value`, checked against its range.
    pub fn set(&mut self, name: &str, value: KnobValue) -> Result<(), String> {
        let at = self.knobs.iter().position(|k| k.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.knobs.iter().map(|k| k.name).collect();
            format!(
                "{}: no knob '{name}' ({})",
                self.technique,
                if names.is_empty() { "it has none".into() } else { format!("it has {}", names.join(", ")) }
            )
        })?;
        self.knobs[at].check(value).map_err(|e| format!("{}: {e}", self.technique))?;
        self.values[at] = value;
        Ok(())
    }

    /// Where the knob `name` is among the technique's knobs.
    fn position(&self, name: &str) -> usize {
        match self.knobs.iter().position(|k| k.name == name) {
            Some(at) => at,
            // A technique reading a knob it does not declare: caught by the test that builds
            // every catalogue entry.
            None => panic!("{} reads a knob it does not declare: {name}", self.technique),
        }
    }

    fn get(&self, name: &str) -> KnobValue {
        self.values[self.position(name)]
    }

    /// A number knob's value.
    pub fn number(&self, name: &str) -> f32 {
        self.get(name).number()
    }

    /// A number knob's value that must be whole.
    pub fn whole(&self, name: &str) -> Result<u32, String> {
        let v = self.number(name);
        if v.fract() != 0.0 {
            return Err(format!("{}: {name} must be a whole number, not {v}", self.technique));
        }
        Ok(v as u32)
    }

    /// A choice knob's option, by name.
    pub fn choice(&self, name: &str) -> &'static str {
        let at = self.position(name);
        match (self.knobs[at].range, self.values[at]) {
            (KnobRange::Choice(options), KnobValue::Choice(i)) => options[i],
            _ => panic!("{}: {name} is not a choice knob", self.technique),
        }
    }

    /// The technique these knobs are for, as errors name it (`ao gtao`).
    pub fn technique(&self) -> &str {
        &self.technique
    }
}
