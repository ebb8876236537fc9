//! `--bench`: per-pass GPU times from timestamp queries over many frames, and the load
//! breakdown, as a table or JSON.

use std::time::Instant;

use serde::Serialize;

use crate::error::PlayResult;
use crate::scene::SectionFate;
use crate::session::{LoadTimes, Session, SessionOptions};

/// Summary of one pass over the measured frames, in milliseconds.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct PassStats {
    /// Pass name.
    pub pass: String,
    /// Median.
    pub median_ms: f64,
    /// 10th percentile.
    pub p10_ms: f64,
    /// 90th percentile.
    pub p90_ms: f64,
    /// Minimum.
    pub min_ms: f64,
    /// Maximum.
    pub max_ms: f64,
}

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Device name.
    pub device: String,
    /// Scene name.
    pub scene: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Frames rendered before measuring.
    pub warmup_frames: u32,
    /// Frames measured.
    pub frames: u32,
    /// Per pass, then "total".
    pub passes: Vec<PassStats>,
    /// Load breakdown.
    pub load: LoadTimes,
    /// Sections and what happened to them.
    pub sections: Vec<SectionFate>,
    /// Validation errors (when validating).
    pub validation_errors: u32,
}

/// The q-quantile (0..=1) of sorted values, linearly interpolated.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let x = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x.fract());
    if i + 1 < sorted.len() { sorted[i] * (1.0 - f) + sorted[i + 1] * f } else { sorted[i] }
}

/// Summary of one pass's samples.
pub fn stats(pass: &str, mut v: Vec<f64>) -> PassStats {
    v.sort_by(f64::total_cmp);
    PassStats {
        pass: pass.to_string(),
        median_ms: quantile(&v, 0.5),
        p10_ms: quantile(&v, 0.1),
        p90_ms: quantile(&v, 0.9),
        min_ms: v.first().copied().unwrap_or(f64::NAN),
        max_ms: v.last().copied().unwrap_or(f64::NAN),
    }
}

/// Runs the benchmark: `warmup` frames, then `frames` measured ones, each waited for (along the
/// options' camera path, when given: the warm-up at its first pose).
pub fn run(options: &SessionOptions, warmup: u32, frames: u32, start: Instant) -> PlayResult<BenchReport> {
    let mut session = Session::open(options, start)?;
    session.follow(options, 0, frames)?;
    // Behind a fallback or with textures streaming: the first frame for the time to the first
    // frame, then every frame measured (warm-up included) shows the chosen techniques and every
    // texture level.
    if session.provisional() {
        session.frame(false)?;
        session.finish_pipelines()?;
    }
    for _ in 0..warmup.max(1) {
        session.frame(false)?;
    }
    let frames = frames.max(1);
    let names: Vec<&str> = session.renderer.pass_names().into_iter().chain(["total"]).collect();
    let mut per_pass: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for f in 0..frames {
        session.follow(options, f, frames)?;
        let t = session.frame(false)?;
        for (i, (_, ms)) in t.iter().enumerate() {
            per_pass[i].push(*ms);
        }
        per_pass[names.len() - 1].push(t.iter().map(|(_, ms)| ms).sum());
    }
    let passes = names.into_iter().zip(per_pass).map(|(n, v)| stats(n, v)).collect();
    let mut report = BenchReport {
        device: session.gpu.name.clone(),
        scene: session.scene.manifest.scene_name.clone(),
        width: options.width,
        height: options.height,
        warmup_frames: warmup.max(1),
        frames,
        passes,
        load: session.times.clone(),
        sections: session.scene.sections.clone(),
        validation_errors: 0,
    };
    report.validation_errors = session.close();
    Ok(report)
}

impl BenchReport {
    /// A human-readable table.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{} on {} at {}x{}: {} frames measured after {} warm-up\n\n{:<10} {:>10} {:>10} {:>10} {:>10} {:>10}\n",
            self.scene,
            self.device,
            self.width,
            self.height,
            self.frames,
            self.warmup_frames,
            "pass",
            "median ms",
            "p10",
            "p90",
            "min",
            "max"
        );
        for p in &self.passes {
            s.push_str(&format!(
                "{:<10} {:>10.3} {:>10.3} {:>10.3} {:>10.3} {:>10.3}\n",
                p.pass, p.median_ms, p.p10_ms, p.p90_ms, p.min_ms, p.max_ms
            ));
        }
        let l = &self.load;
        s.push_str(&format!(
            "\nload (wall clock ms)\n  open file            {:>8.1}\n  instance + device    {:>8.1}\n  validate (parallel)  {:>8.1}\n  decode (in validate and upload) {:>6.1}\n  pipelines (parallel) {:>8.1}\n  upload               {:>8.1}  ({:.1} MiB, {} sections uploaded, {} skipped)\n  first frame on GPU   {:>8.1}\n  resident after start {:>8.1}\n  first frame after start {:>5.1}\n",
            l.open_file_ms,
            l.instance_and_device_ms,
            l.prepare_ms,
            l.decode_ms,
            l.pipelines_ms,
            l.upload_ms,
            l.upload_bytes as f64 / (1 << 20) as f64,
            l.sections_uploaded,
            l.sections_skipped,
            l.first_frame_gpu_ms,
            l.resident_since_start_ms,
            l.first_frame_since_start_ms,
        ));
        if l.fallback.is_empty() {
            s.push_str("  every frame showed the chosen techniques (no fallback)\n");
        } else {
            let shown: Vec<String> =
                l.fallback.iter().map(|f| format!("{} {} for {}", f.effect, f.shown, f.requested)).collect();
            s.push_str(&format!(
                "  fallback shown       {}: {} frame(s) over {:.1} ms\n",
                shown.join(", "),
                l.fallback_frames,
                l.fallback_shown_ms
            ));
        }
        if !l.after_first_frame.is_empty() {
            s.push_str(&format!(
                "  after first frame    {:>8.1}  (uploading {})\n",
                l.rest_upload_ms,
                l.after_first_frame.join(", ")
            ));
        }
        if l.refined_texture_bytes > 0 {
            s.push_str(&format!(
                "  textures refined after start {:>4.1}  ({:.1} MiB coarse before the first frame, {:.1} MiB finer after it)\n",
                l.textures_refined_since_start_ms,
                l.coarse_texture_bytes as f64 / (1 << 20) as f64,
                l.refined_texture_bytes as f64 / (1 << 20) as f64
            ));
        }
        s.push_str(&format!(
            "  chosen pipelines     {:>8.1}\n  chosen ready after start {:>4.1}\n  chosen frame after start {:>4.1}\n",
            l.full_pipelines_ms, l.full_ready_since_start_ms, l.full_frame_since_start_ms
        ));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&v, 0.5), 3.0);
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 1.0), 5.0);
        assert!((quantile(&v, 0.1) - 1.4).abs() < 1e-12);
        assert!(quantile(&[], 0.5).is_nan());
    }
}
