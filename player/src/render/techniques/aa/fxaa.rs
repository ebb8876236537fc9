//! `--aa fxaa`: fast approximate anti-aliasing (Lottes 2009) of every frame's composed radiance
//! (`passes/fxaa.rs`, `shaders/fxaa/`), with the running mean of the stochastic passes of
//! `--aa accumulate` while the camera is still. One frame, no history, no jitter: edges are
//! smoothed from the first frame on, at the cost of a slight blur of fine texture detail.

use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::fxaa::FxaaPass;
use crate::render::techniques::knobs::number;
use crate::render::techniques::{History, Knob, Knobs, Registered, Technique};

/// Accumulation while still, and FXAA.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fxaa {
    /// How much of the sub-pixel blend applies (0 to 1).
    pub subpix: f32,
}

impl Registered for Fxaa {
    const NAME: &'static str = "fxaa";
    const HELP: &'static str = "fast approximate anti-aliasing (Lottes 2009, FXAA 3.11 quality): each frame's edges \
                                found in the composed radiance and blended by the pixels' coverage along them; \
                                the stochastic passes averaged while the camera is still, as with accumulate \
                                (see --fxaa-subpix)";
    const KNOBS: &'static [Knob] = &[number(
        "fxaa-subpix",
        "how much single-pixel features (specks, the ends of thin lines) are blended into their \
         neighbourhood: 0 none, 1 fully; more smooths aliasing more and blurs texture detail more. \
         Lottes's 0.75 is for LDR images: in HDR it spreads bright emitters' edges (the McGuire \
         box's relMSE ×3 against 0.25)",
        0.0,
        1.0,
        0.25,
        &[0.25, 0.75],
    )];

    fn new(k: &Knobs) -> Result<Fxaa, String> {
        Ok(Fxaa { subpix: k.number("fxaa-subpix") })
    }
}

impl Technique for Fxaa {
    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let gpu = frame.gpu;
        let subpix = self.subpix;
        frame.add(Stage::Resolve, move || FxaaPass::new(gpu, subpix));
    }

    fn history(&self) -> History {
        History::Still
    }
}
