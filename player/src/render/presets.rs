//! Named technique sets for the whole frame: what `kiln-play FILE --preset NAME` renders and
//! what kiln-bench's frame chart measures (each with both G-buffers). Every preset carries
//! indirect light — screen-space, path-traced or through the line space — and every preset
//! that traces GI rays denoises it; the emissive surfaces' direct light stays at the default
//! (`--direct restir`, dropped where nothing emits). A preset names only what it changes from
//! the defaults; flags given beside `--preset` override it.

use super::techniques::{Effect, KnobValue, Techniques};

/// One effect's technique in a preset, with the knobs it sets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice {
    /// The effect.
    pub effect: Effect,
    /// Its technique (a catalogue name).
    pub technique: &'static str,
    /// Knobs set away from their defaults.
    pub knobs: &'static [(&'static str, KnobValue)],
}

/// A named technique set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Preset {
    /// Its name (`--preset` value, the frame chart's label).
    pub name: &'static str,
    /// What it is (`--help`, `kiln-bench --list`).
    pub help: &'static str,
    /// What it changes from the default techniques.
    pub choices: &'static [Choice],
}

const fn pick(effect: Effect, technique: &'static str) -> Choice {
    Choice { effect, technique, knobs: &[] }
}

const SHADOW_MAPS: Choice = pick(Effect::Shadows, "shadowmap");
const RT_SHADOWS: Choice = pick(Effect::Shadows, "rt");
const SCREEN_GI: Choice = pick(Effect::Gi, "ssgi");
const SCREEN_REFLECTIONS: Choice = pick(Effect::Reflections, "ssr");
const RT_REFLECTIONS: Choice = pick(Effect::Reflections, "rt");
const RT_GI: Choice = pick(Effect::Gi, "rt");
const RT_GI_2: Choice =
    Choice { effect: Effect::Gi, technique: "rt", knobs: &[("gi-bounces", KnobValue::Number(2.0))] };
const RT_GI_4: Choice =
    Choice { effect: Effect::Gi, technique: "rt", knobs: &[("gi-bounces", KnobValue::Number(4.0))] };
const SVGF: Choice = pick(Effect::Denoise, "svgf");
const TAA: Choice = pick(Effect::Aa, "taa");

const PROBES: Choice = pick(Effect::Gi, "probes");

/// The presets, cheapest first.
pub const PRESETS: [Preset; 10] = [
    Preset {
        name: "baked",
        help: "no rays: shadow maps, screen-space GI and reflections",
        choices: &[SHADOW_MAPS, SCREEN_GI, SCREEN_REFLECTIONS],
    },
    Preset {
        name: "probes",
        help: "no rays: shadow maps, the compiler's irradiance probes for indirect light, screen-space \
               reflections (needs a file compiled with probes)",
        choices: &[SHADOW_MAPS, PROBES, SCREEN_REFLECTIONS],
    },
    Preset {
        name: "baked-taa",
        help: "as baked with temporal anti-aliasing (--aa taa)",
        choices: &[SHADOW_MAPS, SCREEN_GI, SCREEN_REFLECTIONS, TAA],
    },
    Preset {
        name: "hybrid",
        help: "ray-traced shadows, screen-space GI and reflections",
        choices: &[RT_SHADOWS, SCREEN_GI, SCREEN_REFLECTIONS],
    },
    Preset {
        name: "rt",
        help: "ray-traced shadows and reflections, path-traced GI (one bounce), denoised (--denoise svgf)",
        choices: &[RT_SHADOWS, RT_REFLECTIONS, RT_GI, SVGF],
    },
    Preset {
        name: "rt-taa",
        help: "as rt with temporal anti-aliasing: the denoiser's history follows a moving camera",
        choices: &[RT_SHADOWS, RT_REFLECTIONS, RT_GI, SVGF, TAA],
    },
    Preset {
        name: "rt-2",
        help: "as rt with two bounces of GI (--gi-bounces 2)",
        choices: &[RT_SHADOWS, RT_REFLECTIONS, RT_GI_2, SVGF],
    },
    Preset {
        name: "rt-4",
        help: "as rt with four bounces of GI (--gi-bounces 4): closed, bright rooms keep their light",
        choices: &[RT_SHADOWS, RT_REFLECTIONS, RT_GI_4, SVGF],
    },
    Preset {
        name: "rt-4-taa",
        help: "as rt-4 with temporal anti-aliasing",
        choices: &[RT_SHADOWS, RT_REFLECTIONS, RT_GI_4, SVGF, TAA],
    },
    Preset {
        name: "linespace",
        help: "seed 004: shadows and path-traced GI through the line space, denoised (needs a file \
               compiled with line space)",
        choices: &[pick(Effect::Shadows, "linespace"), pick(Effect::Gi, "linespace"), SVGF],
    },
];

impl Preset {
    /// The preset called `name`; the error lists the names.
    pub fn named(name: &str) -> Result<&'static Preset, String> {
        PRESETS.iter().find(|p| p.name == name).ok_or_else(|| {
            let names: Vec<&str> = PRESETS.iter().map(|p| p.name).collect();
            format!("no preset '{name}' (one of: {})", names.join(", "))
        })
    }

    /// What the preset chooses for `effect`, if it chooses.
    pub fn choice(&self, effect: Effect) -> Option<&'static Choice> {
        self.choices.iter().find(|c| c.effect == effect)
    }

    /// Applies the preset's choices to `t`.
    pub fn apply(&self, t: &mut Techniques) {
        for c in self.choices {
            t.set(c.effect, c.technique, c.knobs).expect("a preset names catalogue techniques and knobs");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every preset builds and carries indirect light; the ones that trace GI rays denoise.
    #[test]
    fn every_preset_has_indirect_light_and_traced_gi_is_denoised() {
        for p in &PRESETS {
            let mut t = Techniques::default();
            p.apply(&mut t);
            assert_ne!(t.name_of(Effect::Gi), "none", "{}", p.name);
            if t.get(Effect::Gi).ray_traced() {
                assert_eq!(t.name_of(Effect::Denoise), "svgf", "{}", p.name);
            }
        }
        assert!(Preset::named("nope").unwrap_err().contains("rt-taa"));
    }
}
