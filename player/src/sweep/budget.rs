//! Choosing the whole frame by budget (`kiln-play FILE --budget-ms X`): of the frame presets
//! measured — by the scene's own kiln-bench results (`--bench-results results.json`), else by the
//! table built in here from the committed benchmarks — the one with the lowest error whose frame
//! fits X ms. A point's error is its first measured frame count's (what a moving camera shows;
//! a still one only improves), its time the median GPU ms per frame (not per image), scaled by
//! the pixel count from the size it was measured at to the session's.

use std::path::Path;

use super::results::Results;
use crate::error::{Exit, PlayError, PlayResult};
use crate::render::presets::Preset;

/// One measured technique set.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The G-buffer technique.
    pub gbuffer: String,
    /// The preset.
    pub preset: &'static Preset,
    /// Median GPU ms per frame where it was measured.
    pub frame_ms: f64,
    /// Mean HDR-FLIP against the reference.
    pub flip: f64,
    /// Frames accumulated into the image the error is of.
    pub frames: u32,
}

impl Measured {
    /// `gbuffer/preset`, as kiln-bench's frame chart labels it.
    pub fn label(&self) -> String {
        format!("{}/{}", self.gbuffer, self.preset.name)
    }
}

/// Where the measurements come from.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurements {
    /// What they are ("pica_pica on NVIDIA H200 (built in)").
    pub what: String,
    /// The image size they were measured at.
    pub width: u32,
    /// The image size they were measured at.
    pub height: u32,
    /// The points.
    pub points: Vec<Measured>,
}

/// The built-in table: pica_pica (`tests/scenes/pica_pica.toml`, compiled with the defaults) at
/// 1600 × 900 on an NVIDIA H200 against a 4096-spp all-bounce reference, one frame, the
/// visibility G-buffer (the raster one measured slower at equal error): kiln-bench's frame chart
/// (`kiln-bench --effects frame --frames-accumulated 1,16`, medians of 100 frames), after metal
/// hit by a reflection ray reflected by one more (`docs/benchmarks/metal-bounce/`).
const BUILT_IN: [(&str, &str, f64, f64); 12] = [
    ("visibility", "probes", 0.993, 0.0444),
    ("visibility", "probes-rt", 1.327, 0.0423),
    ("visibility", "baked", 1.331, 0.0584),
    ("visibility", "baked-taa", 1.388, 0.0601),
    ("visibility", "hybrid", 1.663, 0.0574),
    ("visibility", "probes-rt-refl", 1.717, 0.0414),
    ("visibility", "rt", 5.743, 0.0556),
    ("visibility", "rt-taa", 5.899, 0.0576),
    ("visibility", "rt-2", 7.884, 0.0446),
    ("visibility", "rt-4", 10.425, 0.0408),
    ("visibility", "rt-4-taa", 10.591, 0.0430),
    ("visibility", "rt-8", 13.434, 0.0401),
];

/// Whether preset `name` reads the file's irradiance probes.
fn uses_probes(name: &str) -> bool {
    Preset::named(name)
        .ok()
        .and_then(|p| p.choice(crate::render::Effect::Gi))
        .is_some_and(|c| c.technique == "probes")
}

impl Measurements {
    /// The table built in; its probe preset only for a file `with_probes`.
    pub fn built_in(with_probes: bool) -> Measurements {
        let points = BUILT_IN
            .iter()
            .filter(|p| with_probes || !uses_probes(p.1))
            .map(|&(gbuffer, preset, frame_ms, flip)| Measured {
                gbuffer: gbuffer.into(),
                preset: Preset::named(preset).expect("the built-in table names presets"),
                frame_ms,
                flip,
                frames: 1,
            })
            .collect();
        Measurements {
            what: "pica_pica on an NVIDIA H200 (built in: docs/benchmarks/metal-bounce)".into(),
            width: 1600,
            height: 900,
            points,
        }
    }

    /// The frame chart of a kiln-bench `results.json` (the file camera's where there are
    /// several): each preset's point at its fewest frames; presets this player does not know
    /// are left out.
    pub fn from_results(r: &Results) -> Measurements {
        let camera =
            r.points.iter().find(|p| p.effect == "frame").map(|p| p.camera.clone()).unwrap_or_default();
        let mut points: Vec<Measured> = Vec::new();
        for p in r.points.iter().filter(|p| p.effect == "frame" && p.camera == camera) {
            let Some((gbuffer, preset)) = p.technique.split_once('/') else { continue };
            let Ok(preset) = Preset::named(preset) else { continue };
            let m = Measured {
                gbuffer: gbuffer.into(),
                preset,
                frame_ms: p.frame_ms,
                flip: p.error.flip,
                frames: p.frames,
            };
            match points.iter_mut().find(|q| q.label() == m.label()) {
                Some(q) if m.frames < q.frames => *q = m,
                Some(_) => {}
                None => points.push(m),
            }
        }
        Measurements {
            what: format!("{} on {} ({} camera)", r.scene.name, r.device.name, camera),
            width: r.width,
            height: r.height,
            points,
        }
    }

    /// Reads `path` (a kiln-bench results.json).
    pub fn read(path: &Path) -> PlayResult<Measurements> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| PlayError::new(Exit::Io, format!("--bench-results {name}: {e}")))?;
        let m = Measurements::from_results(&Results::from_json(&text, &name)?);
        if m.points.is_empty() {
            return Err(PlayError::new(
                Exit::BadInput,
                format!("--bench-results {name}: no frame chart (run kiln-bench with --effects frame)"),
            ));
        }
        Ok(m)
    }
}

/// The choice and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Chosen {
    /// The point chosen.
    pub point: Measured,
    /// Its frame time at the session's size.
    pub ms: f64,
    /// The sentence `kiln-play` prints.
    pub why: String,
}

/// The point of `m` with the lowest error whose frame, scaled to `width` × `height`, fits
/// `budget_ms` (ties: the faster). Refused (usage error) when none fits, naming the cheapest.
pub fn choose(m: &Measurements, budget_ms: f64, width: u32, height: u32) -> PlayResult<Chosen> {
    let scale = (width as f64 * height as f64) / (m.width as f64 * m.height as f64);
    let scaled = |p: &Measured| p.frame_ms * scale;
    let size = if scale == 1.0 {
        format!("at {}x{}", m.width, m.height)
    } else {
        format!("measured at {}x{}, times scaled by the pixel count to {width}x{height}", m.width, m.height)
    };
    let best = m
        .points
        .iter()
        .filter(|p| scaled(p) <= budget_ms)
        .min_by(|a, b| a.flip.total_cmp(&b.flip).then(a.frame_ms.total_cmp(&b.frame_ms)));
    let Some(best) = best else {
        let cheapest = m.points.iter().min_by(|a, b| a.frame_ms.total_cmp(&b.frame_ms));
        let detail = cheapest.map_or_else(
            || "nothing was measured".to_string(),
            |c| format!("the cheapest, {}, takes {:.3} ms", c.label(), scaled(c)),
        );
        return Err(PlayError::new(
            Exit::Usage,
            format!("--budget-ms {budget_ms}: no technique set fits ({detail}; {}, {size})", m.what),
        ));
    };
    let better = m
        .points
        .iter()
        .filter(|p| p.flip < best.flip)
        .min_by(|a, b| a.frame_ms.total_cmp(&b.frame_ms))
        .map(|p| format!("; the next better, {}, takes {:.3} ms (FLIP {:.4})", p.label(), scaled(p), p.flip))
        .unwrap_or_default();
    let why = format!(
        "--budget-ms {budget_ms}: chose {} (--gbuffer {} --preset {}): {:.3} ms a frame, FLIP {:.4} at {} frame(s), \
         the lowest error within the budget{better} ({}, {size})",
        best.label(),
        best.gbuffer,
        best.preset.name,
        scaled(best),
        best.flip,
        best.frames,
        m.what
    );
    Ok(Chosen { point: best.clone(), ms: scaled(best), why })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(gbuffer: &str, preset: &str, frame_ms: f64, flip: f64) -> Measured {
        Measured {
            gbuffer: gbuffer.into(),
            preset: Preset::named(preset).unwrap(),
            frame_ms,
            flip,
            frames: 1,
        }
    }

    /// Against the brute-force answer: every budget from 0 to 10 ms in 0.05 ms steps, the
    /// chosen point is the lowest-error one of those that fit, and none fits below the cheapest.
    #[test]
    fn the_lowest_error_within_the_budget_is_chosen() {
        let m = Measurements::built_in(false);
        for step in 0..=200 {
            let budget = step as f64 * 0.05;
            let fits: Vec<&(&str, &str, f64, f64)> =
                BUILT_IN.iter().filter(|p| p.2 <= budget && !p.1.starts_with("probes")).collect();
            let expected = fits.iter().map(|p| p.3).fold(f64::INFINITY, f64::min);
            match choose(&m, budget, 1600, 900) {
                Ok(c) => assert_eq!(c.point.flip, expected, "budget {budget}"),
                Err(e) => {
                    assert!(fits.is_empty(), "budget {budget}: refused ({e}) though {} fit", fits.len());
                    assert_eq!(e.exit, Exit::Usage);
                    assert!(e.message.contains("1.331 ms"), "{}", e.message);
                }
            }
        }
        // A quarter of the pixels: a quarter of the time.
        let quarter = BUILT_IN
            .iter()
            .filter(|p| p.2 / 4.0 <= 1.5 && !p.1.starts_with("probes"))
            .map(|p| p.3)
            .fold(f64::INFINITY, f64::min);
        assert_eq!(choose(&m, 1.5, 800, 450).unwrap().point.flip, quarter);
        // A file with probes may choose them: below 1.2 ms nothing else fits.
        let c = choose(&Measurements::built_in(true), 1.0, 1600, 900).unwrap();
        assert_eq!(c.point.preset.name, "probes");
    }

    /// Time per frame, not per image: a point measured at 4 frames (image 4 × its frame time)
    /// fits by its frame time.
    #[test]
    fn the_budget_is_per_frame() {
        let mut slow = point("raster", "rt-taa", 2.0, 0.05);
        slow.frames = 4;
        let m = Measurements {
            what: "test".into(),
            width: 100,
            height: 100,
            points: vec![point("raster", "baked", 1.0, 0.09), slow],
        };
        let c = choose(&m, 3.0, 100, 100).unwrap();
        assert_eq!((c.point.preset.name, c.ms), ("rt-taa", 2.0));
        assert!(c.why.contains("FLIP 0.0500 at 4 frame(s)"), "{}", c.why);
    }
}
