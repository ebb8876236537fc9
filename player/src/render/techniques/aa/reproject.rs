//! `--aa reproject`: the running mean of the ray-traced passes carried along while the camera
//! moves: each pixel's history read where its surface point was last frame, restarted only
//! where that point was hidden (`passes/rt_history.rs`).

use super::reproject_rays;
use crate::render::frame::FrameBuild;
use crate::render::techniques::knobs::{number, whole};
use crate::render::techniques::{History, Knob, Knobs, Registered, Technique};

/// The ray-traced passes' running mean, reprojected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reproject {
    /// The longest history while the camera moves (a still camera's is unbounded).
    pub frames: u32,
}

impl Registered for Reproject {
    const NAME: &'static str = "reproject";
    const HELP: &'static str = "the running mean of the ray-traced passes carried along while the camera moves: \
                                each pixel's history read where its surface point was last frame, restarted only \
                                where that point was hidden (see --history-frames)";
    const KNOBS: &'static [Knob] = &[whole(number(
        "history-frames",
        "the longest history while the camera moves: a new frame weighs at least 1/FRAMES \
         (a still camera's running mean is unbounded)",
        1.0,
        1024.0,
        32.0,
        &[8.0, 32.0],
    ))];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Reproject, String> {
        Ok(Reproject { frames: k.whole("history-frames")? })
    }
}

impl Technique for Reproject {
    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        reproject_rays(frame, self.frames);
    }

    fn history(&self) -> History {
        History::Reprojected(self.frames)
    }
}
