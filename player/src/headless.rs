//! Headless rendering: N frames without a display server, the last one written to a file.

use std::path::Path;
use std::time::Instant;

use crate::error::PlayResult;
use crate::image_out::{OutputKind, write_exr, write_png};
use crate::render::Readback;
use crate::session::{Session, SessionOptions};

/// What a headless run produced.
#[derive(Debug)]
pub struct HeadlessResult {
    /// The session (for its load breakdown and validation count).
    pub session: Session,
    /// Pixels of the EXR that are NaN or infinite (always 0 unless something is wrong).
    pub non_finite: usize,
}

/// Renders `frames` frames (at least one) and writes the last to `output`, if given.
pub fn run(
    options: &SessionOptions,
    frames: u32,
    output: Option<&Path>,
    start: Instant,
) -> PlayResult<HeadlessResult> {
    let kind = output.map(OutputKind::of).transpose()?;
    let mut session = Session::open(options, start)?;
    let mut readback = Readback::new(&session.gpu, options.width, options.height)?;
    let result = (|| -> PlayResult<usize> {
        let frames = frames.max(1);
        for f in 0..frames {
            let last = f + 1 == frames;
            session.frame(if last && output.is_some() { Some(&readback) } else { None })?;
        }
        let (Some(path), Some(kind)) = (output, kind) else { return Ok(0) };
        let (w, h) = (options.width, options.height);
        let mut non_finite = 0;
        match kind {
            OutputKind::Png => {
                let px =
                    readback.display.mapped().map(|m| m[..(w * h * 4) as usize].to_vec()).unwrap_or_default();
                write_png(path, w, h, &px)?;
            }
            OutputKind::Exr => {
                let bytes = readback
                    .radiance
                    .mapped()
                    .map(|m| m[..(w * h * 16) as usize].to_vec())
                    .unwrap_or_default();
                let px: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
                non_finite = px.chunks_exact(4).filter(|p| p[..3].iter().any(|v| !v.is_finite())).count();
                write_exr(path, w, h, &px)?;
            }
        }
        session.times.first_output_since_start_ms = session.since_start_ms();
        Ok(non_finite)
    })();
    readback.destroy(&session.gpu);
    Ok(HeadlessResult { non_finite: result?, session })
}
