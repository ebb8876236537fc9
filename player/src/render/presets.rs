//! Named technique sets for the whole frame: what `kiln-play FILE --preset NAME` renders and
//! what kiln-bench's frame chart measures (each with both G-buffers). Every preset carries
//! indirect light — screen-space, path-traced or through the line space — and every preset
//! that traces GI rays denoises it; the emissive surfaces' direct light stays at the default
//! (`--direct restir`, dropped where nothing emits). A preset names only what it changes from
//! the defaults; flags given beside `--preset` override it.

use kiln_format::KilnFile;
use kiln_format::probes::{PROBE_KINDS, ProbeHeader, ProbeVolume};

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
const RT_REFLECTIONS_HALF: Choice = Choice {
    effect: Effect::Reflections,
    technique: "rt",
    knobs: &[("reflection-res", KnobValue::Choice(1))],
};
const RT_GI: Choice = pick(Effect::Gi, "rt");
const RT_GI_2: Choice =
    Choice { effect: Effect::Gi, technique: "rt", knobs: &[("gi-bounces", KnobValue::Number(2.0))] };
const RT_GI_4: Choice =
    Choice { effect: Effect::Gi, technique: "rt", knobs: &[("gi-bounces", KnobValue::Number(4.0))] };
const RT_GI_8: Choice =
    Choice { effect: Effect::Gi, technique: "rt", knobs: &[("gi-bounces", KnobValue::Number(8.0))] };
const SVGF: Choice = pick(Effect::Denoise, "svgf");
const TAA: Choice = pick(Effect::Aa, "taa");
const FXAA: Choice = pick(Effect::Aa, "fxaa");

const PROBES: Choice = pick(Effect::Gi, "probes");

/// The presets, cheapest first.
pub const PRESETS: [Preset; 13] = [
    Preset {
        name: "baked",
        help: "no rays: shadow maps, screen-space GI and reflections",
        choices: &[SHADOW_MAPS, SCREEN_GI, SCREEN_REFLECTIONS],
    },
    Preset {
        name: "probes",
        help: "no rays: shadow maps, the compiler's irradiance probes for indirect light, screen-space \
               reflections, FXAA (needs a file compiled with probes)",
        choices: &[SHADOW_MAPS, PROBES, SCREEN_REFLECTIONS, FXAA],
    },
    Preset {
        name: "probes-rt",
        help: "as probes with ray-traced soft shadows (--shadows rt): the probes' indirect light, exact \
               direct shadows (needs a file compiled with probes)",
        choices: &[RT_SHADOWS, PROBES, SCREEN_REFLECTIONS, FXAA],
    },
    Preset {
        name: "probes-rt-refl",
        help: "as probes-rt with ray-traced glossy reflections at half resolution, their hits lit by the \
               probes: metal shows the room it mirrors, off screen too (needs a file compiled with probes)",
        choices: &[RT_SHADOWS, PROBES, RT_REFLECTIONS_HALF, FXAA],
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
        name: "rt-8",
        help: "as rt with eight bounces of GI (--gi-bounces 8): white rooms lit by one lamp, where \
               light makes many bounces (McGuire's Cornell box: half rt-4's error)",
        choices: &[RT_SHADOWS, RT_REFLECTIONS, RT_GI_8, SVGF],
    },
    Preset {
        name: "linespace",
        help: "seed 004: shadows and path-traced GI through the line space, denoised (needs a file \
               compiled with line space)",
        choices: &[pick(Effect::Shadows, "linespace"), pick(Effect::Gi, "linespace"), SVGF],
    },
];

/// The preset the default frame of a file uses when the command line chooses no preset or
/// budget: `probes` where the file has irradiance probes (`probes`) and `gi` (the `--gi` given)
/// is none, the best measured point of the frame charts below 2 ms (docs/benchmarks/probes/).
pub fn default_for(probes: bool, gi: Option<&str>) -> Option<&'static Preset> {
    (probes && gi.is_none()).then(|| Preset::named("probes").ok()).flatten()
}

/// Whether `file` holds irradiance probes.
pub fn has_probes(file: &KilnFile) -> bool {
    file.find(kiln_format::sections::PROBE_GRID, 0).is_some()
}

/// The largest share of the light a probe sees straight from emissive surfaces below which the
/// default frame takes their direct light from the probes' emitted layer instead of a per-pixel
/// pass. Khronos ToyCar's 88,837 emissive triangles (its decals) reach 0.6 % at most (median
/// 0.001 %): the per-pixel pass cost 1.6 of the frame's 3.9 ms on an H200 at 1600 × 900 and
/// changed its FLIP by nothing (0.1587 either way); the McGuire box (lit by its lamp) has 48 %
/// at the median, LightsPunctualLamp 18 % at the probe beside its bulb.
pub const DIM_EMITTERS: f32 = 0.01;

/// The probes' largest emitted share ([`crate::scene::probes::emitted_share`]) when `file` has
/// probes and it is below [`DIM_EMITTERS`]; `None` otherwise (no probes, nothing emits, a
/// damaged volume: the session says).
pub fn dim_emitters(file: &KilnFile) -> Option<f32> {
    // The header first: a volume of one layer (nothing emits) needs none of its sections decoded.
    let header = file.group_header::<ProbeHeader>(&PROBE_KINDS, "probe volume").ok()??;
    if header.layers < 2 {
        return None;
    }
    let volume = ProbeVolume::read(file).ok()??;
    crate::scene::probes::emitted_share(&volume).filter(|&s| s < DIM_EMITTERS)
}

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

    /// A file with probes defaults to the probe preset unless --gi is given; one without, or
    /// one that cannot be read, to no preset.
    #[test]
    fn files_with_probes_default_to_the_probe_preset() {
        use kiln_format::{ContentHash, FileWriter, Manifest, sections};
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, probes: bool| {
            let mut w = FileWriter::new();
            w.manifest(&Manifest::default(), ContentHash::default()).unwrap();
            if probes {
                // Only the table is read: the header's bytes need not be a valid volume.
                w.bytes(sections::PROBE_GRID, 0, vec![0u8; 64], ContentHash::default()).unwrap();
            }
            let path = dir.path().join(name);
            std::fs::write(&path, w.to_bytes().unwrap()).unwrap();
            path
        };
        let (with, without) = (write("with.kiln", true), write("without.kiln", false));
        // As the command line asks: an unreadable file has no probes (the session reports it).
        let probes = |path: &std::path::Path| crate::session::open_file(path).is_ok_and(|f| has_probes(&f));
        let chosen = default_for(probes(&with), None).expect("the probe preset");
        assert_eq!(chosen.choice(Effect::Gi).map(|c| c.technique), Some("probes"));
        assert!(default_for(probes(&with), Some("rt")).is_none());
        assert!(default_for(probes(&without), None).is_none());
        assert!(default_for(probes(&dir.path().join("missing.kiln")), None).is_none());
    }
}
