//! Headless rendering: N frames without a display server, the last one written to a file.

use std::path::Path;
use std::time::Instant;

use crate::error::{Exit, PlayError, PlayResult};
use crate::image_out::{OutputKind, write_exr, write_png};
use crate::render::Readable;
use crate::session::{Session, SessionOptions};

/// What a headless run produced.
#[derive(Debug)]
pub struct HeadlessResult {
    /// The session (for its load breakdown and validation count).
    pub session: Session,
    /// Pixels of the EXR that are NaN or infinite (always 0 unless something is wrong).
    pub non_finite: usize,
}

/// Renders `frames` frames (at least one; along the options' camera path, when given) and
/// writes the last to `output`, if given. With a fallback ([`crate::session::PipelineStart`])
/// or textures streaming ([`crate::scene::TextureUpload`]), the first frame comes first, for its
/// time only.
pub fn run(
    options: &SessionOptions,
    frames: u32,
    output: Option<&Path>,
    start: Instant,
) -> PlayResult<HeadlessResult> {
    let kind = output.map(OutputKind::of).transpose()?;
    let mut options = options.clone();
    options.readback =
        kind.map(|k| if k == OutputKind::Exr { Readable::Radiance } else { Readable::Display });
    let mut session = Session::open(&options, start)?;
    let frames = frames.max(1);
    // Behind a fallback, or with textures streaming, the first frame is rendered and timed (what
    // a window shows first) but not written: every frame below shows the chosen techniques and
    // every texture level.
    if session.provisional() {
        session.follow(&options, 0, frames)?;
        session.frame(false)?;
        session.finish_pipelines()?;
        // When the chosen pipelines were ready before that frame, it was already theirs and
        // nothing restarted after it: restart here, so that the written frame never depends on
        // when the pipelines were ready.
        session.restart();
    }
    for f in 0..frames {
        session.follow(&options, f, frames)?;
        session.frame(f + 1 == frames && output.is_some())?;
    }
    let (Some(path), Some(kind)) = (output, kind) else {
        return Ok(HeadlessResult { session, non_finite: 0 });
    };
    let (w, h) = (options.width, options.height);
    let texel = if kind == OutputKind::Exr { 16 } else { 4 };
    let bytes = session
        .readback
        .as_mut()
        .and_then(|r| r.buffer.mapped())
        .map(|m| m[..(w as usize * h as usize * texel)].to_vec())
        .ok_or_else(|| PlayError::new(Exit::Gpu, "the readback buffer is not host-visible"))?;
    let mut non_finite = 0;
    match kind {
        OutputKind::Png => write_png(path, w, h, &bytes)?,
        OutputKind::Exr => {
            let px: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
            non_finite = px.chunks_exact(4).filter(|p| p[..3].iter().any(|v| !v.is_finite())).count();
            write_exr(path, w, h, &px)?;
        }
    }
    session.times.first_output_since_start_ms = session.since_start_ms();
    Ok(HeadlessResult { session, non_finite })
}
