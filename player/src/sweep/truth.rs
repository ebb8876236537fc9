//! The reference a sweep measures against, and its own error bar.
//!
//! The path tracer renders the image twice with independent random sequences, N/2 samples per
//! pixel each; the reference is their mean (N samples). How far the two halves disagree is the
//! reference's noise floor: an error smaller than that cannot be told from the reference's own
//! noise. For RMSE the N-sample reference's expected error is half the halves' RMSE (the
//! difference of two independent N/2-sample means has four times the variance of one N-sample
//! mean), for relMSE a quarter; mean FLIP does not scale, so its floor is the halves' FLIP as it
//! is (a slight overestimate of the N-sample image's).
//!
//! Both halves are cached in the output folder under a key of everything that decides them:
//! the file's content, the camera, the size, the samples, the seed and the path tracer's SPIR-V.

use std::path::{Path, PathBuf};
use std::time::Instant;

use xxhash_rust::xxh3::Xxh3;

use crate::error::{Exit, PlayError, PlayResult};
use crate::image_out::read_exr;
use crate::reference::{DEFAULT_SEED, MAX_PATH, Sampling, read_spp, render_with, write_exr};
use crate::render::spirv;
use crate::session::SessionOptions;

use super::results::{Figures, ReferenceInfo};

/// The second half's seed: 2^31 away from the first, so that its sample sequence (index × the
/// golden ratio + seed, hashed) never meets the first half's.
const SECOND_SEED: u32 = DEFAULT_SEED.wrapping_add(1 << 31);

/// A reference image and what the results say of it (samples, bounces, noise floor, cache).
#[derive(Debug, Clone)]
pub struct Reference {
    /// Linear RGB radiance, the mean of both halves.
    pub rgb: Vec<f32>,
    /// Its record in the results.
    pub info: ReferenceInfo,
}

/// The cache key of a reference: hex of a 128-bit hash.
pub fn key(content_hash: &str, camera: &str, width: u32, height: u32, spp: u32, bounces: u32) -> String {
    let mut h = Xxh3::new();
    for part in [content_hash.as_bytes(), camera.as_bytes(), spirv::shader!("reference/pathtrace.comp")] {
        h.update(&(part.len() as u64).to_le_bytes());
        h.update(part);
    }
    for n in [width, height, spp, bounces, MAX_PATH, DEFAULT_SEED, SECOND_SEED] {
        h.update(&n.to_le_bytes());
    }
    format!("{:032x}", h.digest128())
}

/// The halves' files in `dir`.
pub fn files(dir: &Path, key: &str) -> [PathBuf; 2] {
    [dir.join(format!("{key}-a.exr")), dir.join(format!("{key}-b.exr"))]
}

/// Renders (or loads from `dir`) the reference of `spp` samples (rounded up to even) and
/// `bounces` (0: all) for the camera and size of `base` (named `camera` in the results), cached
/// under `key`.
pub fn obtain(
    base: &SessionOptions,
    camera: &str,
    spp: u32,
    bounces: u32,
    key: &str,
    dir: &Path,
    mut progress: impl FnMut(&str),
) -> PlayResult<Reference> {
    let half = spp.div_ceil(2).max(1);
    let (w, h) = (base.width, base.height);
    std::fs::create_dir_all(dir)
        .map_err(|e| PlayError::new(Exit::Io, format!("{}: cannot create the folder: {e}", dir.display())))?;
    let mut halves = Vec::new();
    let mut seconds = 0.0;
    let mut cached = true;
    for (path, seed) in files(dir, key).into_iter().zip([DEFAULT_SEED, SECOND_SEED]) {
        if let Some(rgb) = load(&path, w, h, half) {
            halves.push(rgb);
            continue;
        }
        cached = false;
        progress(&format!("reference: {half} samples per pixel, seed {seed:#x}"));
        let t = Instant::now();
        let sampling = Sampling { spp: half, seed, bounces, progress: false };
        let (_, rgb) = render_with(base, sampling, Instant::now())?;
        seconds += t.elapsed().as_secs_f64();
        write_exr(&path, w, h, &rgb, half)?;
        halves.push(rgb);
    }
    let (a, b) = (&halves[0], &halves[1]);
    let between = kiln_metrics::compare(super::rgb_image(w, h, a), super::rgb_image(w, h, b))
        .map_err(|e| PlayError::new(Exit::Gpu, format!("the reference halves cannot be compared: {e}")))?;
    let noise_floor =
        Figures { flip: between.flip, rel_mse: between.rel_mse / 4.0, rmse: between.rmse / 2.0 };
    let rgb = a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect();
    let info = ReferenceInfo {
        camera: camera.to_string(),
        spp: 2 * half,
        bounces,
        noise_floor,
        seconds,
        cached,
        key: key.to_string(),
    };
    Ok(Reference { rgb, info })
}

/// A cached half, if `path` holds one of the right size and sample count.
fn load(path: &Path, width: u32, height: u32, spp: u32) -> Option<Vec<f32>> {
    if read_spp(path)? != spp {
        return None;
    }
    let (w, h, rgb) = read_exr(path).ok()?;
    (w == width && h == height && rgb.iter().all(|v| v.is_finite())).then_some(rgb)
}
