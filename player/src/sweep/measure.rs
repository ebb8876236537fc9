//! Rendering one configuration: its images at each frame count it is measured at, then its
//! GPU time per frame over many frames.

use std::time::Instant;

use crate::bench::{PassStats, stats};
use crate::error::{Exit, PlayError, PlayResult};
use crate::render::{Readable, RenderSettings, Techniques};
use crate::session::{Session, SessionOptions};

/// What one configuration produced.
#[derive(Debug, Clone)]
pub struct Measured {
    /// (frames accumulated, linear RGB radiance) at each checkpoint.
    pub images: Vec<(u32, Vec<f32>)>,
    /// Per pass, then "total", over the timed frames.
    pub passes: Vec<PassStats>,
    /// Notes from the session (lights left unshadowed, ...).
    pub warnings: Vec<String>,
}

/// How many frames to time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Timing {
    /// Frames rendered and discarded before timing (after the checkpoints).
    pub warmup: u32,
    /// Frames timed.
    pub frames: u32,
}

/// Renders `techniques` in a session of its own: every checkpoint's image (along the options'
/// camera path, when given, over as many frames as the last checkpoint), then `timing` (at the
/// path's last pose).
pub fn measure(
    base: &SessionOptions,
    techniques: Techniques,
    checkpoints: &[u32],
    timing: Timing,
    mut tick: impl FnMut(),
) -> PlayResult<Measured> {
    let mut options = base.clone();
    options.render = RenderSettings { techniques, ..options.render };
    options.readback = Some(Readable::Radiance);
    let mut session = Session::open(&options, Instant::now())?;
    let result = run(&mut session, &options, checkpoints, timing, &mut tick);
    let warnings = session.warnings.clone();
    let errors = session.close();
    crate::gpu::process::release_freed_memory();
    let mut measured = result?;
    if errors > 0 {
        return Err(PlayError::new(Exit::Gpu, format!("the validation layer reported {errors} error(s)")));
    }
    measured.warnings = warnings;
    Ok(measured)
}

fn run(
    session: &mut Session,
    options: &SessionOptions,
    checkpoints: &[u32],
    timing: Timing,
    tick: &mut dyn FnMut(),
) -> PlayResult<Measured> {
    // Every measured frame shows the chosen techniques (a no-op unless the options ask for a
    // fallback).
    session.finish_pipelines()?;
    let (w, h) = (session.renderer.images().width as usize, session.renderer.images().height as usize);
    let last = checkpoints.iter().copied().max().unwrap_or(1).max(1);
    let mut images = Vec::new();
    for frame in 1..=last {
        session.follow(options, frame - 1, last)?;
        let read = checkpoints.contains(&frame);
        session.frame(read)?;
        if read {
            let bytes = session
                .readback
                .as_mut()
                .and_then(|r| r.buffer.mapped())
                .ok_or_else(|| PlayError::new(Exit::Gpu, "the readback buffer is not host-visible"))?;
            let rgba: &[f32] = bytemuck::cast_slice(&bytes[..w * h * 16]);
            images.push((frame, rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect()));
            tick();
        }
    }
    for _ in 0..timing.warmup {
        session.frame(false)?;
    }
    let names: Vec<&str> = session.renderer.pass_names().into_iter().chain(["total"]).collect();
    let mut per_pass: Vec<Vec<f64>> = vec![Vec::with_capacity(timing.frames as usize); names.len()];
    for _ in 0..timing.frames.max(1) {
        let t = session.frame(false)?;
        for (i, (_, ms)) in t.iter().enumerate() {
            per_pass[i].push(*ms);
        }
        per_pass[names.len() - 1].push(t.iter().map(|(_, ms)| ms).sum());
    }
    let passes = names.into_iter().zip(per_pass).map(|(n, v)| stats(n, v)).collect();
    Ok(Measured { images, passes, warnings: Vec::new() })
}
