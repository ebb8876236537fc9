//! What happens to the stochastic passes' samples across frames: accumulation and
//! anti-aliasing.

use super::{History, techniques};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::rt_history::RtHistoryPass;

techniques! {
    /// Accumulation and anti-aliasing.
    Aa for Aa, default accumulate::Accumulate;
    none => Off,
    accumulate => Accumulate,
    reproject => Reproject,
    taa => Taa,
    fxaa => Fxaa,
}

impl Aa {
    /// Whether frames are jittered and resolved through a history.
    pub fn temporal(&self) -> bool {
        self.technique().temporal()
    }

    /// Whether the stochastic passes keep a running mean while the camera is still.
    pub fn accumulates(&self) -> bool {
        self.technique().history() != History::None
    }

    /// The longest history of the ray-traced passes while the camera moves, when it is
    /// reprojected (`None`: it restarts at every move, or there is none).
    pub fn reprojected(&self) -> Option<u32> {
        match self.technique().history() {
            History::Reprojected(frames) => Some(frames),
            History::None | History::Still => None,
        }
    }
}

/// The reprojected accumulation of the ray-traced passes' targets, when any pass traces rays,
/// capped at `frames` while the camera moves.
fn reproject_rays(frame: &mut FrameBuild<'_>, frames: u32) {
    if frame.techniques.ray_traced() {
        let lights = frame.scene.lights;
        let targets = frame.techniques.each().filter_map(|t| t.accumulated(lights)).collect();
        let gpu = frame.gpu;
        frame.add(Stage::Accumulate, move || RtHistoryPass::new(gpu, targets, frames));
    }
}
