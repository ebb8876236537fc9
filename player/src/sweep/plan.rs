//! What a sweep renders: for each effect, every technique the catalogue lists with every value
//! of its quality knobs, the other effects fixed; and the frame as a whole in a few presets.
//! Built from [`catalogue`] alone, so a new technique or knob is swept without naming it here.

use std::collections::BTreeMap;
use std::fmt;

use crate::render::presets::PRESETS;
use crate::render::techniques::{
    Knob, KnobRange, KnobRole, KnobValue, TechniqueInfo, catalogue, techniques_of,
};
use crate::render::{Effect, Needs, Techniques};
use crate::scene::linespace::variants_needed;
use kiln_format::linespace::Variants;

/// What one chart of a sweep shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Target {
    /// One effect's techniques, everything else fixed.
    Effect(Effect),
    /// Whole-frame presets.
    Frame,
}

impl Target {
    /// Every target `--effects` accepts, in the order they are swept.
    pub const ALL: [Target; 9] = [
        Target::Effect(Effect::Shadows),
        Target::Effect(Effect::Direct),
        Target::Effect(Effect::Ao),
        Target::Effect(Effect::Reflections),
        Target::Effect(Effect::Gi),
        Target::Effect(Effect::Denoise),
        Target::Effect(Effect::Media),
        Target::Effect(Effect::Aa),
        Target::Frame,
    ];

    /// The name `--effects` takes.
    pub fn name(self) -> &'static str {
        match self {
            Target::Effect(e) => e.name(),
            Target::Frame => "frame",
        }
    }

    /// The target called `name`.
    pub fn parse(name: &str) -> Result<Target, String> {
        Target::ALL.into_iter().find(|t| t.name() == name).ok_or_else(|| {
            let names: Vec<&str> = Target::ALL.iter().map(|t| t.name()).collect();
            format!("no effect '{name}' (one of: {})", names.join(", "))
        })
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The light transport a chart's reference computes: the bounces (scattering events) whose
/// light counts, 0 for all. Shadows and AO approximate direct light (from the lights and the
/// sky), so their charts compare against direct light alone; media techniques approximate
/// single scattering, the direct light of a scattering event in the medium, so theirs against
/// one bounce too (surfaces lit directly, the medium scattering once); reflections add one
/// glossy bounce, so theirs against two bounces; indirect light and the whole frame against
/// every bounce, the truth. Against all bounces a frame without indirect light is mostly wrong
/// by what it leaves out, which would hide the difference between two shadow (or media)
/// techniques.
pub fn bounces(target: Target) -> u32 {
    match target {
        // The anti-aliasing chart holds the frame at shadow maps and the sky's ambient: direct
        // light.
        Target::Effect(Effect::Shadows | Effect::Direct | Effect::Ao | Effect::Media | Effect::Aa) => 1,
        Target::Effect(Effect::Reflections) => 2,
        _ => 0,
    }
}

/// How [`bounces`] reads in a sentence.
pub fn transport(bounces: u32) -> String {
    match bounces {
        0 => "all bounces".into(),
        1 => "direct light only (1 bounce)".into(),
        n => format!("{n} bounces"),
    }
}

/// What the file offers the techniques (decided from its sections before any rendering).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Offers {
    /// A BVH (ray-traced techniques, the reference).
    pub bvh: bool,
    /// Shadow maps for at least one light.
    pub shadow_maps: bool,
    /// The line-space variants in the file (`kiln_format::linespace::Variants`; 0: none).
    pub line_space: u32,
    /// A participating medium.
    pub media: bool,
    /// An emissive material (the direct light of emissive surfaces has something to sample).
    pub emission: bool,
    /// An analytic light (without one, shadow maps have nothing to shadow: a technique that
    /// reads them renders what the default frame does).
    pub lights: bool,
    /// The irradiance probe volume.
    pub probes: bool,
}

impl Offers {
    /// Why `techniques` cannot run on this file, if they cannot.
    pub fn lacks(&self, techniques: &Techniques) -> Option<String> {
        let n: Needs = techniques.needs();
        let variants = variants_needed(n.line_space);
        if n.bvh && !self.bvh {
            Some("needs the BVH, which the file does not have (compiled without one)".into())
        } else if n.shadow_maps && !self.shadow_maps && self.lights {
            Some(
                "needs shadow maps, which the file does not have (compiled with shadows skipped, or no lights)"
                    .into(),
            )
        } else if n.probes && !self.probes {
            Some("needs irradiance probes, which the file does not have (compiled with --probes off, or nothing lights it)".into())
        } else if n.media && !self.media {
            Some("needs a participating medium, which the file does not have (add a [[medium]] to the sidecar)".into())
        } else if variants & !self.line_space != 0 {
            Some(format!(
                "needs the line space's {}, which the file does not have (compile with --shaft-variants {})",
                Variants::list(variants & !self.line_space),
                Variants::list(variants | self.line_space)
            ))
        } else {
            None
        }
    }
}

/// One configuration to render: a technique with its knob values, the rest fixed.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    /// The chart it belongs to.
    pub target: Target,
    /// Technique name (for the frame: the preset's name).
    pub technique: String,
    /// Knob values as text, by knob name (only knobs the sweep varies or the user set).
    pub knobs: BTreeMap<String, String>,
    /// Everything the frame renders.
    pub techniques: Techniques,
    /// Frames accumulated at which the image is measured (ascending; `[1]` for deterministic
    /// techniques).
    pub checkpoints: Vec<u32>,
}

impl Config {
    /// A short label for charts: technique, knob values, frames.
    pub fn label(&self, frames: u32) -> String {
        let mut s = self.technique.clone();
        for v in self.knobs.values() {
            s.push(' ');
            s.push_str(v);
        }
        if self.checkpoints.len() > 1 || frames > 1 {
            s.push_str(&format!(" {frames}f"));
        }
        s
    }
}

/// A technique the sweep leaves out, and why.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Skipped {
    /// Effect (or "frame").
    pub effect: String,
    /// Technique or preset.
    pub technique: String,
    /// Why.
    pub reason: String,
}

/// Everything one sweep renders.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Configurations by chart, in sweep order.
    pub configs: Vec<Config>,
    /// What was left out.
    pub skipped: Vec<Skipped>,
    /// The techniques every effect chart holds fixed (except its own effect).
    pub fixed: Techniques,
}

/// What the user asked to sweep.
#[derive(Debug, Clone)]
pub struct Request {
    /// Charts to make.
    pub targets: Vec<Target>,
    /// `EFFECT:TECHNIQUE` or `TECHNIQUE` filters; empty: everything.
    pub techniques: Vec<String>,
    /// Frames accumulated at which stochastic techniques are measured.
    pub frames: Vec<u32>,
    /// Every combination of every technique's quality knobs (`--exhaustive`); otherwise one
    /// knob at a time around the defaults, refined along the Pareto front ([`refine`]).
    pub exhaustive: bool,
}

impl Request {
    fn wants(&self, target: Target, technique: &str) -> bool {
        self.techniques.is_empty()
            || self.techniques.iter().any(|f| match f.split_once(':') {
                Some((e, t)) => e == target.name() && t == technique,
                None => f == technique,
            })
    }

    /// Checks the technique filters against the catalogue (and the frame presets): a filter
    /// that matches nothing is a typo the user should hear about.
    pub fn check(&self) -> Result<(), String> {
        for f in &self.techniques {
            let known = Target::ALL.iter().any(|&target| {
                names(target).iter().any(|t| match f.split_once(':') {
                    Some((e, n)) => e == target.name() && n == *t,
                    None => f == t,
                })
            });
            if !known {
                return Err(format!(
                    "--techniques: '{f}' matches no technique (write EFFECT:TECHNIQUE or TECHNIQUE, e.g. ao:rt; `kiln-bench --list` shows them)"
                ));
            }
        }
        if self.frames.is_empty() || self.frames.contains(&0) {
            return Err("--frames-accumulated needs at least one count, each at least 1".into());
        }
        Ok(())
    }
}

/// Technique (or preset) names of a target.
pub fn names(target: Target) -> Vec<&'static str> {
    match target {
        Target::Effect(e) => techniques_of(e).map(|t| t.name).collect(),
        Target::Frame => PRESETS.iter().map(|p| p.name).collect(),
    }
}

fn set(t: &mut Techniques, effect: Effect, name: &str) {
    t.set(effect, name, &[]).expect("a catalogue technique");
}

/// The techniques effect charts hold fixed: raster G-buffer, shadow maps where the file has
/// them (else none), every other effect off (the emissive surfaces' direct light too),
/// accumulation on.
pub fn fixed(offers: &Offers) -> Techniques {
    let mut t = Techniques::default();
    // Raster, as the charts were measured with; the frame chart compares both G-buffers.
    set(&mut t, Effect::GBuffer, "raster");
    set(&mut t, Effect::Shadows, if offers.shadow_maps { "shadowmap" } else { "none" });
    set(&mut t, Effect::Direct, "none");
    set(&mut t, Effect::Aa, "accumulate");
    t
}

/// What an effect's chart holds fixed: [`fixed`], except that the chart of the emissive
/// surfaces' direct light traces their shadow rays (`--shadows none` would leave them
/// unshadowed), and the denoiser's chart renders what it filters: path-traced GI, and the
/// emissive surfaces' direct light (ray-traced shadows) where the file emits.
fn fixed_for(effect: Effect, offers: &Offers) -> Techniques {
    let mut t = fixed(offers);
    if matches!(effect, Effect::Direct | Effect::Denoise) && offers.bvh {
        set(&mut t, Effect::Shadows, "rt");
    }
    if effect == Effect::Denoise && offers.bvh {
        set(&mut t, Effect::Gi, "rt");
        if offers.emission {
            set(&mut t, Effect::Direct, "restir");
        }
    }
    t
}

/// A technique's knob values as a sweep sets them: (knob, value, its text).
type Combo = Vec<(&'static str, KnobValue, String)>;

/// A knob, the values a sweep measures (each with its text) and its default.
type SweptKnob = (&'static Knob, Vec<(KnobValue, String)>, (KnobValue, String));

/// The values a sweep measures of each of a technique's quality knobs (scene knobs stay at their
/// defaults; a number knob with fewer than two sweep values is not varied), in sweep order, and
/// the knob's default.
fn swept_values(info: &TechniqueInfo) -> Vec<SweptKnob> {
    let mut out = Vec::new();
    for k in info.knobs.iter().filter(|k| k.role == KnobRole::Quality) {
        let text = |v: KnobValue| match k.range {
            KnobRange::Choice(options) => options[v.number() as usize].to_string(),
            KnobRange::Number { .. } => v.number().to_string(),
        };
        let values: Vec<KnobValue> = match k.range {
            KnobRange::Number { sweep, .. } if sweep.len() > 1 => {
                sweep.iter().map(|&v| KnobValue::Number(v)).collect()
            }
            KnobRange::Number { .. } => continue,
            KnobRange::Choice(options) => (0..options.len()).map(KnobValue::Choice).collect(),
        };
        out.push((k, values.into_iter().map(|v| (v, text(v))).collect(), (k.default, text(k.default))));
    }
    out
}

/// The knob combinations a sweep measures of a technique: with `exhaustive` every combination of
/// the swept values; otherwise the defaults and each knob varied alone over its other swept
/// values (1 + Σ values instead of Π values: SSGI's 2 × 2 × 3 × 2 × 5 = 120 become at most
/// 15), which [`refine`] completes along the Pareto front once they are measured.
fn knob_combinations(info: &TechniqueInfo, exhaustive: bool) -> Vec<Combo> {
    let knobs = swept_values(info);
    if !exhaustive {
        let defaults: Combo = knobs.iter().map(|(k, _, d)| (k.name, d.0, d.1.clone())).collect();
        let mut combos = vec![defaults.clone()];
        for (i, (_, values, default)) in knobs.iter().enumerate() {
            for (v, text) in values.iter().filter(|(v, _)| *v != default.0) {
                let mut c = defaults.clone();
                c[i] = (c[i].0, *v, text.clone());
                combos.push(c);
            }
        }
        return combos;
    }
    product(knobs.into_iter().map(|(k, values, _)| (k.name, values)))
}

/// Every combination of one value of each knob: (knob, its values) in order.
fn product(knobs: impl Iterator<Item = (&'static str, Vec<(KnobValue, String)>)>) -> Vec<Combo> {
    let mut combos: Vec<Combo> = vec![Vec::new()];
    for (name, values) in knobs {
        combos = combos
            .into_iter()
            .flat_map(|c| {
                values.iter().map(move |(v, text)| {
                    let mut c = c.clone();
                    c.push((name, *v, text.clone()));
                    c
                })
            })
            .collect();
    }
    combos
}

/// The configuration of `info`'s chart at the knob values `combo`, the chart's other effects
/// fixed ([`fixed_for`]); `checkpoints` says at which frame counts, from its techniques.
fn effect_config(
    info: &TechniqueInfo,
    combo: &Combo,
    offers: &Offers,
    checkpoints: impl FnOnce(&Techniques) -> Vec<u32>,
) -> Config {
    let mut t = fixed_for(info.effect, offers);
    let values: Vec<(&str, KnobValue)> = combo.iter().map(|(n, v, _)| (*n, *v)).collect();
    t.set(info.effect, info.name, &values).expect("catalogue values are valid");
    Config {
        target: Target::Effect(info.effect),
        technique: info.name.to_string(),
        knobs: combo.iter().map(|(n, _, text)| (n.to_string(), text.clone())).collect(),
        checkpoints: checkpoints(&t),
        techniques: t,
    }
}

/// The most configurations [`refine`] adds per technique.
pub const REFINE_PER_TECHNIQUE: usize = 8;

/// The refinement of a one-knob-at-a-time sweep: for each technique with two or more varied
/// knobs, the combinations of the values its points on the chart's Pareto front (`front`: chart,
/// technique, knob texts) show for each knob, not measured yet (`planned`), at most
/// [`REFINE_PER_TECHNIQUE`], best-guess first (the front points' own values come first).
pub fn refine(
    request: &Request,
    offers: &Offers,
    planned: &[Config],
    front: &[(Target, String, BTreeMap<String, String>)],
) -> Vec<Config> {
    let mut out = Vec::new();
    if request.exhaustive {
        return out;
    }
    for info in catalogue() {
        let target = Target::Effect(info.effect);
        let on_front: Vec<&BTreeMap<String, String>> =
            front.iter().filter(|(t, n, _)| *t == target && n == info.name).map(|(_, _, k)| k).collect();
        let knobs = swept_values(info);
        if on_front.is_empty() || knobs.len() < 2 {
            continue;
        }
        let template = planned.iter().find(|c| c.target == target && c.technique == info.name);
        let Some(template) = template else { continue };
        let seen = knobs.into_iter().map(|(k, mut values, default)| {
            if !values.contains(&default) {
                values.insert(0, default);
            }
            values.retain(|(_, text)| on_front.iter().any(|f| f.get(k.name) == Some(text)));
            (k.name, values)
        });
        let mut added = 0;
        for combo in product(seen) {
            if added == REFINE_PER_TECHNIQUE {
                break;
            }
            let config = effect_config(info, &combo, offers, |_| template.checkpoints.clone());
            let known = planned
                .iter()
                .chain(&out)
                .any(|c| c.target == target && c.technique == info.name && c.knobs == config.knobs);
            if !known {
                out.push(config);
                added += 1;
            }
        }
    }
    out
}

/// The plan for `request` on a file that `offers` what it offers.
pub fn plan(request: &Request, offers: &Offers) -> Plan {
    let fixed = fixed(offers);
    let mut configs = Vec::new();
    let mut skipped = Vec::new();
    let checkpoints = |stochastic: bool, t: &Techniques| {
        if stochastic && t.aa.accumulates() { request.frames.clone() } else { vec![1] }
    };
    for &target in &request.targets {
        match target {
            Target::Effect(effect) => {
                for info in catalogue().iter().filter(|t| t.effect == effect) {
                    if !request.wants(target, info.name) {
                        continue;
                    }
                    if effect == Effect::Direct && info.name != "none" && !offers.emission {
                        push_skip(&mut skipped, target, info.name, "nothing in the file emits light");
                        continue;
                    }
                    for combo in knob_combinations(info, request.exhaustive) {
                        // A frame that traces rays improves with frames whatever the effect's
                        // technique (the denoiser's `none` among them).
                        let config = effect_config(info, &combo, offers, |t| {
                            checkpoints(info.stochastic || t.ray_traced(), t)
                        });
                        if let Some(reason) = offers.lacks(&config.techniques) {
                            push_skip(&mut skipped, target, info.name, &reason);
                            continue;
                        }
                        configs.push(config);
                    }
                }
            }
            Target::Frame => {
                for preset in &PRESETS {
                    let name = preset.name;
                    if !request.wants(target, name) {
                        continue;
                    }
                    for gbuffer in techniques_of(Effect::GBuffer) {
                        let mut t = Techniques::default();
                        set(&mut t, Effect::Aa, "accumulate");
                        set(&mut t, Effect::GBuffer, gbuffer.name);
                        if !offers.emission {
                            // What a session does with such a file: nothing to sample.
                            set(&mut t, Effect::Direct, "none");
                        }
                        preset.apply(&mut t);
                        if let Some(reason) = offers.lacks(&t) {
                            push_skip(&mut skipped, target, name, &reason);
                            continue;
                        }
                        configs.push(Config {
                            target,
                            technique: format!("{}/{name}", gbuffer.name),
                            knobs: BTreeMap::new(),
                            techniques: t,
                            checkpoints: checkpoints(
                                t.ray_traced() || t.aa.temporal() || t.reads_previous_frame(),
                                &t,
                            ),
                        });
                    }
                }
            }
        }
    }
    Plan { configs, skipped, fixed }
}

fn push_skip(skipped: &mut Vec<Skipped>, target: Target, technique: &str, reason: &str) {
    let s = Skipped { effect: target.name().into(), technique: technique.into(), reason: reason.into() };
    if !skipped.contains(&s) {
        skipped.push(s);
    }
}

/// "gbuffer raster, shadows shadowmap, ..." for the effects other than `except`, from a map
/// of effect to technique.
pub fn describe_fixed_map(fixed: &BTreeMap<String, String>, except: &str) -> String {
    Effect::ALL
        .iter()
        .filter(|e| e.name() != except)
        .filter_map(|e| fixed.get(e.name()).map(|t| format!("{e} {t}")))
        .collect::<Vec<_>>()
        .join(", ")
}

/// One line per preset for `--list`.
pub fn preset_help() -> Vec<String> {
    PRESETS.iter().map(|p| format!("{}: {} (with each G-buffer)", p.name, p.help)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(targets: Vec<Target>, techniques: &[&str]) -> Request {
        Request {
            targets,
            techniques: techniques.iter().map(|s| s.to_string()).collect(),
            frames: vec![1, 4],
            exhaustive: true,
        }
    }

    const ALL_OFFERED: Offers = Offers {
        bvh: true,
        shadow_maps: true,
        line_space: Variants::ALL,
        media: true,
        emission: true,
        lights: true,
        probes: true,
    };

    #[test]
    fn every_catalogue_technique_of_an_effect_is_swept() {
        let p = plan(&request(vec![Target::Effect(Effect::Shadows)], &[]), &ALL_OFFERED);
        let names: Vec<&str> = p.configs.iter().map(|c| c.technique.as_str()).collect();
        // rt's knobs size the lights: held at their defaults, so one rt configuration; linespace
        // has one quality knob of two choices.
        assert_eq!(names, ["none", "shadowmap", "rt", "linespace", "linespace"]);
        assert_eq!(p.configs[2].checkpoints, [1, 4]);
        assert_eq!(p.configs[1].checkpoints, [1]);
        let r = plan(&request(vec![Target::Effect(Effect::Reflections)], &["reflections:rt"]), &ALL_OFFERED);
        // resolution (2 options) × max roughness (2 sweep values) × metal bounce (2 sweep values)
        assert_eq!(r.configs.len(), 8);
        assert!(r.configs.iter().all(|c| c.techniques.name_of(Effect::Shadows) == "shadowmap"));
        let ao = plan(&request(vec![Target::Effect(Effect::Ao)], &[]), &ALL_OFFERED);
        // none, rt at each reach (the absolute radius has one sweep value: not varied), sao's
        // samples × resolutions and gtao's slices × steps (their reach held at 0.05)
        let mut expected = vec!["none".to_string()];
        expected.extend(["0.03", "0.1", "0.3", "100"].map(|r| format!("rt {r} 1f")));
        for n in [8, 16, 32] {
            expected.extend(["full", "half"].map(|res| format!("sao {res} {n}")));
        }
        for slices in [2, 3, 9] {
            expected.extend([2, 3, 8].map(|steps| format!("gtao {slices} {steps}")));
        }
        assert_eq!(ao.configs.iter().map(|c| c.label(1)).collect::<Vec<_>>(), expected);
    }

    /// The default sweep varies one knob at a time: per technique the defaults and each knob's
    /// other swept values (counted here from the catalogue's data), not the product of the
    /// swept values; the whole default sweep of a file that offers everything stays within 127
    /// configurations (before the refinement's at most 8 per technique) while the exhaustive one
    /// is more than twice as large.
    #[test]
    fn the_default_sweep_varies_one_knob_at_a_time_and_is_bounded() {
        let mut one = request(Target::ALL.to_vec(), &[]);
        one.exhaustive = false;
        let all = request(Target::ALL.to_vec(), &[]);
        let (p1, px) = (plan(&one, &ALL_OFFERED), plan(&all, &ALL_OFFERED));
        for info in catalogue() {
            let counts: Vec<(usize, usize)> = info
                .knobs
                .iter()
                .filter(|k| k.role == KnobRole::Quality)
                .filter_map(|k| match k.range {
                    KnobRange::Choice(o) => Some((o.len(), 1)),
                    KnobRange::Number { sweep, .. } if sweep.len() > 1 => {
                        Some((sweep.len(), sweep.contains(&k.default.number()) as usize))
                    }
                    KnobRange::Number { .. } => None,
                })
                .collect();
            // Each knob's swept values but its default, if swept, beside the defaults.
            let expected_one = 1 + counts.iter().map(|(n, has_default)| n - has_default).sum::<usize>();
            let expected_all: usize = counts.iter().map(|(n, _)| n).product();
            let target = Target::Effect(info.effect);
            let n = |p: &Plan| {
                p.configs.iter().filter(|c| c.target == target && c.technique == info.name).count()
            };
            if n(&px) == 0 {
                continue; // skipped (e.g. nothing emits) in both
            }
            assert_eq!(n(&p1), expected_one, "{} {}", info.effect, info.name);
            assert_eq!(n(&px), expected_all, "{} {}", info.effect, info.name);
        }
        // Measured: 127 against 284 (frame presets 26 of them in both).
        assert!(p1.configs.len() <= 127, "the default sweep plans {} configurations", p1.configs.len());
        assert!(px.configs.len() > 2 * p1.configs.len(), "{} against {}", px.configs.len(), p1.configs.len());
    }

    /// The refinement measures the combinations of the values the front shows per knob, and
    /// nothing already measured; nothing for an exhaustive sweep.
    #[test]
    fn refinement_combines_the_fronts_values() {
        let mut one = request(vec![Target::Effect(Effect::Denoise)], &[]);
        one.exhaustive = false;
        let p = plan(&one, &ALL_OFFERED);
        let knobs = |i: &str, s: &str, t: &str| -> BTreeMap<String, String> {
            [("denoise-iterations", i), ("denoise-sigma-luminance", s), ("denoise-taps", t)]
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .into()
        };
        let target = Target::Effect(Effect::Denoise);
        // The front holds iterations 3 (sigma 8) and sigma 16 (iterations 5): both values of
        // each, 3x3 alone: 2 × 2 × 1 combinations, of which (5, 8) and (3, 8) and (5, 16) were
        // measured: (3, 16) is new.
        let front = vec![
            (target, "svgf".to_string(), knobs("3", "8", "3x3")),
            (target, "svgf".to_string(), knobs("5", "16", "3x3")),
        ];
        let r = refine(&one, &ALL_OFFERED, &p.configs, &front);
        assert_eq!(r.iter().map(|c| c.knobs.clone()).collect::<Vec<_>>(), [knobs("3", "16", "3x3")]);
        assert_eq!(r[0].techniques.name_of(Effect::Gi), "rt", "the chart's fixed frame");
        assert!(refine(&request(vec![target], &[]), &ALL_OFFERED, &p.configs, &front).is_empty());
    }

    #[test]
    fn missing_sections_skip_with_a_reason() {
        let p = plan(
            &request(Target::ALL.to_vec(), &[]),
            &Offers {
                bvh: false,
                shadow_maps: false,
                line_space: 0,
                media: false,
                emission: false,
                lights: true,
                probes: false,
            },
        );
        assert!(
            p.configs
                .iter()
                .all(|c| !c.techniques.ray_traced() && c.techniques.name_of(Effect::Shadows) != "shadowmap")
        );
        assert!(
            p.skipped.iter().any(|s| s.effect == "ao" && s.technique == "rt" && s.reason.contains("BVH"))
        );
        assert!(p.skipped.iter().any(|s| s.technique == "shadowmap" && s.reason.contains("shadow maps")));
        assert!(p.skipped.iter().any(|s| s.technique == "march" && s.reason.contains("[[medium]]")));
        // With the BVH but no line space, the feelers are skipped, naming the variant they need.
        let offers = Offers {
            bvh: true,
            shadow_maps: true,
            line_space: 0,
            media: false,
            emission: false,
            lights: true,
            probes: false,
        };
        let p = plan(&request(vec![Target::Effect(Effect::Shadows)], &[]), &offers);
        assert!(
            p.skipped
                .iter()
                .any(|s| s.technique == "linespace" && s.reason.contains("--shaft-variants binary"))
        );
        assert!(p.configs.iter().all(|c| c.technique != "linespace"));
    }

    #[test]
    fn filters_are_checked() {
        assert!(request(vec![], &["ao:rt", "shadowmap", "frame:rt-taa"]).check().is_ok());
        let e = request(vec![], &["ao:shadowmap"]).check().unwrap_err();
        assert!(e.contains("ao:shadowmap"), "{e}");
        assert!(Target::parse("fog").unwrap_err().contains("shadows, direct, ao"));
    }
}
