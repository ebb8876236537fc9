//! The flags `kiln-play` makes from the technique catalogue: one per effect choosing its
//! technique, one per knob (a knob several techniques share is one flag, under the heading of the
//! first effect that has it), each with its range and defaults in `--help`; and what the parsed
//! flags say ([`TechniqueFlags`]).

use clap::builder::{PossibleValue, PossibleValuesParser};
use clap::{Arg, ArgAction, ArgMatches, Command};

use crate::render::presets::Preset;
use crate::render::techniques::{Effect, Knob, KnobRange, KnobValue, Techniques, catalogue, techniques_of};

/// What the catalogue's flags say: each effect's technique and the knob values given.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TechniqueFlags {
    /// (effect, technique name), every effect (its default when not given).
    chosen: Vec<(Effect, String)>,
    /// (knob, value) of every knob flag given.
    knobs: Vec<(&'static str, KnobValue)>,
    /// `--no-accumulate`.
    pub(super) no_accumulate: bool,
}

impl TechniqueFlags {
    /// The technique chosen for `effect` (its catalogue default when the flag is absent).
    pub(super) fn technique(&self, effect: Effect) -> &str {
        self.chosen.iter().find(|(e, _)| *e == effect).map_or_else(|| default_technique(effect), |(_, n)| n)
    }

    /// The technique a flag names for `effect`, if one does.
    pub(super) fn given(&self, effect: Effect) -> Option<&str> {
        self.chosen.iter().find(|(e, _)| *e == effect).map(|(_, n)| n.as_str())
    }

    /// The value the command line gives the knob `name`.
    pub(super) fn knob(&self, name: &str) -> Option<KnobValue> {
        self.knobs.iter().find(|(k, _)| *k == name).map(|(_, v)| *v)
    }

    /// The techniques the flags choose over `preset`'s choices (and its knobs), with
    /// `gbuffer` (the budget's choice) unless `--gbuffer` is given: a flag naming another
    /// technique than the preset's replaces it, knob flags override the preset's knobs. Errors
    /// name the flag and the valid values.
    pub(super) fn techniques(
        &self,
        preset: Option<&Preset>,
        gbuffer: Option<&str>,
    ) -> Result<Techniques, String> {
        let mut t = Techniques::default();
        for effect in Effect::ALL {
            let none = effect == Effect::Aa && self.no_accumulate;
            let given = if none { Some("none") } else { self.given(effect) };
            // The preset's choice (and its knobs) unless a flag names another technique.
            let preset_choice =
                preset.and_then(|p| p.choice(effect)).filter(|c| given.is_none_or(|g| g == c.technique));
            let budget_gbuffer = gbuffer.filter(|_| effect == Effect::GBuffer);
            let name = given
                .or(preset_choice.map(|c| c.technique))
                .or(budget_gbuffer)
                .unwrap_or_else(|| self.technique(effect));
            let knobs: Vec<(&str, KnobValue)> = techniques_of(effect)
                .find(|i| i.name == name)
                .map(|i| {
                    i.knobs
                        .iter()
                        .filter_map(|k| {
                            let from_preset =
                                preset_choice.and_then(|c| c.knobs.iter().find(|(n, _)| *n == k.name));
                            self.knob(k.name).or(from_preset.map(|(_, v)| *v)).map(|v| (k.name, v))
                        })
                        .collect()
                })
                .unwrap_or_default();
            t.set(effect, name, &knobs).map_err(|e| format!("--{effect} {name}: {e}"))?;
        }
        Ok(t)
    }

    pub(super) fn from_matches(m: &ArgMatches) -> TechniqueFlags {
        let chosen = Effect::ALL
            .into_iter()
            .filter_map(|e| m.get_one::<String>(e.name()).map(|n| (e, n.clone())))
            .collect();
        let knobs = knob_flags()
            .into_iter()
            .filter_map(|(_, k)| m.get_one::<KnobValue>(k.name).map(|v| (k.name, *v)))
            .collect();
        TechniqueFlags { chosen, knobs, no_accumulate: m.get_flag("no_accumulate") }
    }
}

/// The technique `Techniques::default()` uses for `effect`.
fn default_technique(effect: Effect) -> &'static str {
    Techniques::default().name_of(effect)
}

/// Every knob of the catalogue once (knobs shared by several techniques, e.g. `--ao-radius`,
/// have one flag), in catalogue order, with the first effect whose techniques declare it (under
/// whose heading its flag stands).
fn knob_flags() -> Vec<(Effect, &'static Knob)> {
    let mut seen: Vec<(Effect, &'static Knob)> = Vec::new();
    for info in catalogue() {
        for k in info.knobs {
            if !seen.iter().any(|(_, s)| s.name == k.name) {
                seen.push((info.effect, k));
            }
        }
    }
    seen
}

/// The `--help` text of the knob flag `knob` of `effect`: which techniques read it, what it
/// does, its range and each technique's default.
fn knob_help(effect: Effect, knob: &Knob) -> String {
    let users: Vec<(&str, &Knob)> = techniques_of(effect)
        .filter_map(|t| t.knobs.iter().find(|k| k.name == knob.name).map(|k| (t.name, k)))
        .collect();
    let names: Vec<&str> = users.iter().map(|(n, _)| *n).collect();
    let range = match knob.range {
        KnobRange::Number { min, max, whole, .. } => {
            let max = if max.is_infinite() { "∞".to_string() } else { max.to_string() };
            format!("{}{min} to {max}", if whole { "a whole number, " } else { "" })
        }
        KnobRange::Choice(options) => options.join(", "),
    };
    let defaults: Vec<String> = if users.iter().all(|(_, k)| k.default == knob.default) {
        vec![knob.default_text()]
    } else {
        users.iter().map(|(n, k)| format!("{n} {}", k.default_text())).collect()
    };
    let names = match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => names.join(""),
    };
    format!("With --{effect} {names}: {} ({range}) [default: {}]", knob.help, defaults.join(", "))
}

/// A knob flag's parser: the text as the knob's value, checked against its range (whichever
/// technique is chosen: a bad value is an error even where no technique reads it).
fn knob_parser(
    knob: &'static Knob,
) -> impl Fn(&str) -> Result<KnobValue, String> + Clone + Send + Sync + 'static {
    move |s: &str| {
        let v = knob.parse(s)?;
        knob.check(v)?;
        Ok(v)
    }
}

/// `cmd` with every effect's technique flag and every knob flag, a heading per effect.
pub(super) fn add(mut cmd: Command) -> Command {
    for effect in Effect::ALL {
        let heading = effect.title();
        let values = techniques_of(effect).map(|t| PossibleValue::new(t.name).help(t.help));
        cmd = cmd.arg(
            Arg::new(effect.name())
                .long(effect.name())
                .value_name("TECHNIQUE")
                .value_parser(PossibleValuesParser::new(values))
                .help(format!("{} technique [default: {}]", heading, default_technique(effect)))
                .help_heading(heading),
        );
        if effect == Effect::Aa {
            cmd = cmd.arg(
                Arg::new("no_accumulate")
                    .long("no-accumulate")
                    .action(ArgAction::SetTrue)
                    .conflicts_with("aa")
                    .help("Do not average the ray-traced passes over frames (every frame shows one sample): the same as --aa none")
                    .help_heading(heading)
                    .hide_short_help(true),
            );
        }
        for (_, knob) in knob_flags().into_iter().filter(|(first, _)| *first == effect) {
            let value_name = match knob.range {
                KnobRange::Number { whole: true, .. } => "N".to_string(),
                KnobRange::Number { .. } => "X".to_string(),
                KnobRange::Choice(_) => "CHOICE".to_string(),
            };
            let mut arg = Arg::new(knob.name)
                .long(knob.name)
                .value_name(value_name)
                .allow_negative_numbers(true)
                .value_parser(clap::builder::ValueParser::new(knob_parser(knob)))
                .help(knob_help(effect, knob))
                .help_heading(heading)
                .hide_short_help(true);
            if let KnobRange::Choice(options) = knob.range {
                arg = arg.hide_possible_values(true).value_name(options.join("|"));
            }
            cmd = cmd.arg(arg);
        }
    }
    cmd
}
