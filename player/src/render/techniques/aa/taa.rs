//! `--aa taa`: temporal anti-aliasing (seed 000, after Karis 2014): the projection jittered by a
//! Halton (2, 3) sub-pixel offset each frame, the frame blended into a history reprojected from
//! the previous frame's camera, the history clamped to the current frame's neighbourhood in
//! YCoCg (`passes/taa.rs`, `shaders/taa/`). The ray-traced passes' running mean is reprojected
//! as with `--aa reproject`, capped at the same length.

use super::reproject_rays;
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::taa::TaaPass;
use crate::render::techniques::knobs::{choice, number, whole};
use crate::render::techniques::{History, Knob, Knobs, Registered, Technique};

/// Temporal anti-aliasing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Taa {
    /// The longest history in frames: a pixel's new sample weighs 1/min(n + 1, frames) after n
    /// frames of history.
    pub frames: u32,
    /// Blend with Karis's luminance weights c / (1 + luma) (the seed's; damps fireflies,
    /// darkens high-contrast edges) instead of linearly.
    pub luma_weights: bool,
}

impl Registered for Taa {
    const NAME: &'static str = "taa";
    const HELP: &'static str = "temporal anti-aliasing (seed 000): a Halton sub-pixel jitter per frame, each frame \
                                blended into a history reprojected from the last camera and clamped to the \
                                current neighbourhood (YCoCg); the ray-traced passes' running mean reprojected \
                                as with reproject, at most --taa-frames long while moving; see --taa-frames, \
                                --taa-weights";
    const KNOBS: &'static [Knob] = &[
        whole(number(
            "taa-frames",
            "the longest history in frames: a new frame weighs at least 1/FRAMES (the seed's \
             blend 0.88–0.97 is 8–33 frames); longer converges further on a still camera and \
             smears more on a moving one",
            1.0,
            1024.0,
            16.0,
            &[4.0, 8.0, 16.0, 32.0],
        )),
        choice(
            "taa-weights",
            "luma: blend c/(1 + luma) (Karis's, the seed's: damps fireflies, darkens \
             high-contrast edges); linear: blend the radiance itself (converges to the \
             supersampled image)",
            &["luma", "linear"],
            1,
        ),
    ];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Taa, String> {
        Ok(Taa { frames: k.whole("taa-frames")?, luma_weights: k.choice("taa-weights") == "luma" })
    }
}

impl Technique for Taa {
    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        reproject_rays(frame, self.frames);
        let gpu = frame.gpu;
        frame.add(Stage::Resolve, move || TaaPass::new(gpu, self.frames, self.luma_weights));
    }

    fn history(&self) -> History {
        History::Reprojected(self.frames)
    }

    fn temporal(&self) -> bool {
        true
    }
}
