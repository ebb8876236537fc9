//! What a sweep records: the schema of `results.json`, its CSV twin, and the comparison of two
//! runs (`--compare`).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::bench::PassStats;
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::DeviceIdentity;

use super::plan::Skipped;

/// Version of the `results.json` layout; a reader refuses other versions.
pub const SCHEMA: u32 = 1;

/// One error measurement of an image against the reference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Figures {
    /// Mean HDR-FLIP.
    pub flip: f64,
    /// Mean relative squared error, (t − r)² / (r² + 0.01) per channel.
    pub rel_mse: f64,
    /// Root mean squared error over pixels and channels (linear radiance).
    pub rmse: f64,
}

impl From<kiln_metrics::Errors> for Figures {
    fn from(e: kiln_metrics::Errors) -> Figures {
        Figures { flip: e.flip, rel_mse: e.rel_mse, rmse: e.rmse }
    }
}

/// The scene swept.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneInfo {
    /// Scene name from the manifest.
    pub name: String,
    /// The `.kiln` file as given.
    pub file: String,
    /// XXH3-128 of the whole file (hex).
    pub content_hash: String,
}

/// The reference of one camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceInfo {
    /// The camera (`file` or the `--camera` value).
    pub camera: String,
    /// Samples per pixel (two independent halves).
    pub spp: u32,
    /// Bounces whose light the reference counts (0: all, 1: direct light only).
    pub bounces: u32,
    /// The errors of an image indistinguishable from the reference.
    pub noise_floor: Figures,
    /// Seconds spent path tracing it in this run (0: from the cache).
    pub seconds: f64,
    /// Whether it came from the cache.
    pub cached: bool,
    /// Cache key (the halves are `reference/KEY-a.exr`, `-b.exr`).
    pub key: String,
}

/// One measured image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// The chart: an effect, or "frame".
    pub effect: String,
    /// Technique (frame: `gbuffer/preset`).
    pub technique: String,
    /// Knob values the sweep set, by knob name.
    pub knobs: BTreeMap<String, String>,
    /// Frames accumulated into the image.
    pub frames: u32,
    /// Chart label.
    pub label: String,
    /// The camera.
    pub camera: String,
    /// Every effect's technique in this frame.
    pub techniques: BTreeMap<String, String>,
    /// GPU ms per frame: median, 10th and 90th percentile.
    pub frame_ms: f64,
    /// 10th percentile of the frame time.
    pub frame_p10_ms: f64,
    /// 90th percentile of the frame time.
    pub frame_p90_ms: f64,
    /// Median GPU ms of the passes this technique adds to the chart's fixed frame.
    pub effect_ms: f64,
    /// GPU ms the image took: frames × median frame time.
    pub image_ms: f64,
    /// Every pass over the timed frames (and "total").
    pub passes: Vec<PassStats>,
    /// Error against the reference.
    pub error: Figures,
    /// The reference's samples per pixel.
    pub reference_spp: u32,
    /// The reference's bounce limit (0: all).
    pub reference_bounces: u32,
    /// The reference's noise floor.
    pub noise_floor: Figures,
    /// Whether the FLIP error is below the noise floor (not a win: indistinguishable).
    pub below_noise_floor: bool,
    /// Whether no other point of its chart and camera is at once faster and more accurate.
    pub on_front: bool,
    /// Set by `--compare`: how this point regressed against the old run.
    pub regression: Option<String>,
}

/// Timing settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct TimingInfo {
    /// Frames rendered before timing.
    pub warmup_frames: u32,
    /// Frames timed per configuration.
    pub frames: u32,
}

/// A whole sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Results {
    /// [`SCHEMA`].
    pub schema: u32,
    /// The tool and its version.
    pub tool: String,
    /// The device.
    pub device: DeviceIdentity,
    /// The scene.
    pub scene: SceneInfo,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Timing settings.
    pub timing: TimingInfo,
    /// How the errors are defined.
    pub metrics: String,
    /// The techniques every effect chart holds fixed (its own effect aside).
    pub fixed: BTreeMap<String, String>,
    /// One reference per camera.
    pub references: Vec<ReferenceInfo>,
    /// Every point.
    pub points: Vec<Point>,
    /// Techniques left out, with the reason.
    pub skipped: Vec<Skipped>,
    /// Notes (lights left unshadowed, ...).
    pub warnings: Vec<String>,
    /// Wall-clock seconds of the whole sweep, reference included.
    pub sweep_seconds: f64,
}

/// What [`Results::metrics`] says.
pub const METRICS: &str = "flip: mean HDR-FLIP (Andersson et al. 2021; 67 pixels per degree, exposures from the reference); \
     rel_mse: mean over pixels and channels of (test - ref)^2 / (ref^2 + 0.01); \
     rmse: sqrt of the mean over pixels and channels of (test - ref)^2, linear radiance; \
     noise floor: the two half-sample references compared (flip as is, rmse / 2, rel_mse / 4)";

impl Results {
    /// Parses `results.json`, refusing other schema versions.
    pub fn from_json(text: &str, name: &str) -> PlayResult<Results> {
        let v: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| PlayError::new(Exit::BadInput, format!("{name}: not JSON: {e}")))?;
        match v.get("schema").and_then(|s| s.as_u64()) {
            Some(s) if s == SCHEMA as u64 => {}
            Some(s) => {
                return Err(PlayError::new(
                    Exit::BadInput,
                    format!("{name}: results schema {s}; this kiln-bench reads schema {SCHEMA}"),
                ));
            }
            None => {
                return Err(PlayError::new(
                    Exit::BadInput,
                    format!("{name}: no \"schema\": not a kiln-bench results file"),
                ));
            }
        }
        serde_json::from_value(v).map_err(|e| PlayError::new(Exit::BadInput, format!("{name}: {e}")))
    }

    /// The JSON text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("plain data serialises")
    }

    /// The CSV text: one row per point, the header first.
    pub fn to_csv(&self) -> String {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record(CSV_COLUMNS).expect("writing to memory");
        for p in &self.points {
            let knobs: Vec<String> = p.knobs.iter().map(|(k, v)| format!("{k}={v}")).collect();
            let row = [
                p.effect.clone(),
                p.technique.clone(),
                knobs.join(";"),
                p.frames.to_string(),
                p.label.clone(),
                p.camera.clone(),
                p.frame_ms.to_string(),
                p.frame_p10_ms.to_string(),
                p.frame_p90_ms.to_string(),
                p.effect_ms.to_string(),
                p.image_ms.to_string(),
                p.error.flip.to_string(),
                p.error.rel_mse.to_string(),
                p.error.rmse.to_string(),
                p.reference_spp.to_string(),
                p.reference_bounces.to_string(),
                p.noise_floor.flip.to_string(),
                p.noise_floor.rel_mse.to_string(),
                p.noise_floor.rmse.to_string(),
                p.below_noise_floor.to_string(),
                p.on_front.to_string(),
                p.regression.clone().unwrap_or_default(),
                self.device.name.clone(),
                self.device.driver_version.clone(),
                self.device.uuid.clone(),
                self.scene.content_hash.clone(),
            ];
            w.write_record(row).expect("writing to memory");
        }
        String::from_utf8(w.into_inner().expect("flushing to memory")).expect("UTF-8 fields")
    }
}

/// The CSV header.
pub const CSV_COLUMNS: [&str; 26] = [
    "effect",
    "technique",
    "knobs",
    "frames",
    "label",
    "camera",
    "frame_ms",
    "frame_p10_ms",
    "frame_p90_ms",
    "effect_ms",
    "image_ms",
    "flip",
    "rel_mse",
    "rmse",
    "reference_spp",
    "reference_bounces",
    "floor_flip",
    "floor_rel_mse",
    "floor_rmse",
    "below_noise_floor",
    "on_front",
    "regression",
    "device",
    "driver",
    "gpu_uuid",
    "scene_hash",
];

/// Marks each point of its chart and camera that no other point beats in both time and error.
pub fn mark_front(points: &mut [Point]) {
    let mut groups: BTreeMap<(String, String), Vec<usize>> = BTreeMap::new();
    for (i, p) in points.iter().enumerate() {
        groups.entry((p.effect.clone(), p.camera.clone())).or_default().push(i);
    }
    for members in groups.values() {
        let xy: Vec<(f64, f64)> =
            members.iter().map(|&i| (points[i].image_ms, points[i].error.flip)).collect();
        let front = kiln_plot::pareto_front(&xy);
        for (k, &i) in members.iter().enumerate() {
            points[i].on_front = front.contains(&k);
        }
    }
}

/// Regression thresholds of `--compare`: a time must grow by more than this fraction (and more
/// than the two runs' own spread) to count, an error by more than this fraction and
/// [`ERROR_FLOOR`].
pub const TIME_TOLERANCE: f64 = 0.05;
/// Relative growth of an error that counts.
pub const ERROR_TOLERANCE: f64 = 0.02;
/// Absolute growth of mean FLIP that counts.
pub const ERROR_FLOOR: f64 = 5e-4;

/// Compares `new` with `old` point by point (same chart, technique, knobs, frames, camera) and
/// records in each new point whether it regressed: slower at equal error, or worse at equal
/// time. Returns notes (points without a partner, a different device or scene).
pub fn compare(new: &mut Results, old: &Results) -> Vec<String> {
    let mut notes = Vec::new();
    if new.device.uuid != old.device.uuid {
        notes.push(format!(
            "the old run is from another device ({} {}, this: {} {}): times differ for that reason too",
            old.device.name, old.device.uuid, new.device.name, new.device.uuid
        ));
    }
    if new.scene.content_hash != old.scene.content_hash {
        notes.push("the old run is of another file (content hash differs)".into());
    }
    if (new.width, new.height) != (old.width, old.height) {
        notes.push(format!(
            "the old run is at {}x{}, this one at {}x{}",
            old.width, old.height, new.width, new.height
        ));
    }
    let key =
        |p: &Point| (p.effect.clone(), p.technique.clone(), p.knobs.clone(), p.frames, p.camera.clone());
    let olds: BTreeMap<_, &Point> = old.points.iter().map(|p| (key(p), p)).collect();
    let mut unmatched = 0;
    for p in &mut new.points {
        let Some(o) = olds.get(&key(p)) else {
            unmatched += 1;
            continue;
        };
        p.regression = regression(p, o);
    }
    if unmatched > 0 {
        notes.push(format!("{unmatched} point(s) have no partner in the old run"));
    }
    notes
}

/// Why `new` is a regression from `old`, if it is.
pub fn regression(new: &Point, old: &Point) -> Option<String> {
    let spread = |p: &Point| (p.frame_p90_ms - p.frame_p10_ms).max(0.0) / p.frame_ms.max(1e-12) * 0.5;
    let time_tol = TIME_TOLERANCE.max(spread(new)).max(spread(old));
    let slower = new.image_ms > old.image_ms * (1.0 + time_tol);
    let faster = new.image_ms < old.image_ms * (1.0 - time_tol);
    let err_tol = (old.error.flip * ERROR_TOLERANCE).max(ERROR_FLOOR);
    let worse = new.error.flip > old.error.flip + err_tol;
    let better = new.error.flip < old.error.flip - err_tol;
    let pct = |a: f64, b: f64| (a / b.max(1e-12) - 1.0) * 100.0;
    if slower && !better {
        Some(format!(
            "slower: {:.4} ms, was {:.4} ms ({:+.1}%), error {:.4} was {:.4}",
            new.image_ms,
            old.image_ms,
            pct(new.image_ms, old.image_ms),
            new.error.flip,
            old.error.flip
        ))
    } else if worse && !faster {
        Some(format!(
            "worse: mean FLIP {:.4}, was {:.4} ({:+.1}%), time {:.4} ms was {:.4} ms",
            new.error.flip,
            old.error.flip,
            pct(new.error.flip, old.error.flip),
            new.image_ms,
            old.image_ms
        ))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(effect: &str, frames: u32, image_ms: f64, flip: f64) -> Point {
        Point {
            effect: effect.into(),
            technique: "rt".into(),
            knobs: BTreeMap::from([("ao-reach".to_string(), "0.1".to_string())]),
            frames,
            label: format!("rt 0.1 {frames}f"),
            camera: "file".into(),
            techniques: BTreeMap::from([("ao".to_string(), "rt".to_string())]),
            frame_ms: image_ms / frames as f64,
            frame_p10_ms: image_ms / frames as f64 * 0.99,
            frame_p90_ms: image_ms / frames as f64 * 1.01,
            effect_ms: 0.25,
            image_ms,
            passes: vec![PassStats {
                pass: "total".into(),
                median_ms: image_ms / frames as f64,
                p10_ms: 0.0,
                p90_ms: 0.0,
                min_ms: 0.0,
                max_ms: 0.0,
            }],
            error: Figures { flip, rel_mse: 0.5, rmse: 1e-3 },
            reference_spp: 64,
            reference_bounces: 1,
            noise_floor: Figures { flip: 0.01, rel_mse: 1e-4, rmse: 1e-5 },
            below_noise_floor: false,
            on_front: true,
            regression: None,
        }
    }

    fn results(points: Vec<Point>) -> Results {
        Results {
            schema: SCHEMA,
            tool: "kiln-bench test".into(),
            device: DeviceIdentity { name: "gpu \"x\", y".into(), uuid: "00ff".into(), ..Default::default() },
            scene: SceneInfo { name: "s".into(), file: "s.kiln".into(), content_hash: "ab".into() },
            width: 4,
            height: 3,
            timing: TimingInfo { warmup_frames: 1, frames: 2 },
            metrics: METRICS.into(),
            fixed: BTreeMap::new(),
            references: vec![],
            points,
            skipped: vec![],
            warnings: vec![],
            sweep_seconds: 1.5,
        }
    }

    #[test]
    fn json_round_trips_and_other_schemas_are_refused() {
        let r = results(vec![point("ao", 4, 2.0, 0.1), point("ao", 16, 8.0, 1.0 / 3.0)]);
        assert_eq!(Results::from_json(&r.to_json(), "r.json").unwrap(), r);
        let other = r.to_json().replacen(&format!("\"schema\": {SCHEMA}"), "\"schema\": 99", 1);
        assert!(Results::from_json(&other, "r.json").unwrap_err().message.contains("schema 99"));
        assert!(
            Results::from_json("{}", "r.json").unwrap_err().message.contains("not a kiln-bench results file")
        );
    }

    #[test]
    fn csv_has_a_row_per_point_with_quoted_fields() {
        let r = results(vec![point("ao", 4, 2.0, 0.1)]);
        let csv = r.to_csv();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].split(',').count(), CSV_COLUMNS.len());
        // The device name has a comma and quotes: quoted, quotes doubled.
        assert!(lines[1].contains("\"gpu \"\"x\"\", y\""), "{}", lines[1]);
        assert!(lines[1].contains(",0.1,0.5,0.001,"), "{}", lines[1]);
    }

    #[test]
    fn regressions_are_slower_at_equal_error_or_worse_at_equal_time() {
        let old = point("ao", 4, 2.0, 0.1);
        // Within tolerances: not a regression.
        assert_eq!(regression(&point("ao", 4, 2.05, 0.1005), &old), None);
        // 20% slower, same error.
        assert!(regression(&point("ao", 4, 2.4, 0.1), &old).unwrap().starts_with("slower"));
        // Slower but clearly more accurate: a trade, not a regression.
        assert_eq!(regression(&point("ao", 4, 2.4, 0.05), &old), None);
        // Same time, 10% worse.
        assert!(regression(&point("ao", 4, 2.0, 0.11), &old).unwrap().starts_with("worse"));
        // Worse but clearly faster: a trade.
        assert_eq!(regression(&point("ao", 4, 1.5, 0.11), &old), None);
        let mut new = results(vec![point("ao", 4, 2.4, 0.1), point("ao", 64, 1.0, 0.1)]);
        let notes = compare(&mut new, &results(vec![old]));
        assert!(new.points[0].regression.is_some() && new.points[1].regression.is_none());
        assert_eq!(notes, ["1 point(s) have no partner in the old run"]);
    }
}
