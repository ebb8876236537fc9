//! `--media sousa`: Sousa's sun shafts (seed 002): three chained radial blurs of the depth map
//! with steps TAPS⁻¹, TAPS⁻², TAPS⁻³ (`passes/sousa.rs`, `shaders/sousa/`). Image space, as
//! Mitchell.

use super::{MEDIA_RES, no_medium};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::sousa::SousaPass;
use crate::render::techniques::knobs::{UNBOUNDED, number, scene, whole};
use crate::render::techniques::{Knob, Knobs, Needs, Registered, ScreenFraction, Technique};

/// Sousa's sun shafts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sousa {
    /// Samples per pass (TAPS).
    pub taps: u32,
    /// Resolution of the depth map and the first two passes.
    pub resolution: ScreenFraction,
    /// The factor on each pass's sum at 6 taps (scaled by 6/TAPS for other counts).
    pub brightness: f32,
}

impl Registered for Sousa {
    const NAME: &'static str = "sousa";
    const HELP: &'static str = "Sousa's sun shafts (seed 002, CryEngine): the depth map blurred radially towards \
                                each light in three chained passes of TAPS samples (steps 1/TAPS, 1/TAPS², 1/TAPS³ \
                                of the screen); image space, as mitchell; see --media-taps, --media-res, \
                                --media-brightness";
    const KNOBS: &'static [Knob] = &[
        whole(number("media-taps", "samples per pass (TAPS; 3 passes)", 1.0, 64.0, 6.0, &[3.0, 6.0, 10.0])),
        MEDIA_RES,
        // Artistic: a sweep holds it at its default.
        scene(number(
            "media-brightness",
            "factor on each pass's sum at 6 taps (the seed's 0.19), scaled by 6/TAPS for others",
            0.0,
            UNBOUNDED,
            0.19,
            &[],
        )),
    ];

    fn new(k: &Knobs) -> Result<Sousa, String> {
        Ok(Sousa {
            taps: k.whole("media-taps")?,
            resolution: ScreenFraction::named(k.choice("media-res")),
            brightness: k.number("media-brightness"),
        })
    }
}

impl Technique for Sousa {
    fn needs(&self) -> Needs {
        Needs { media: true, ..Needs::NONE }
    }

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let gpu = frame.gpu;
        frame.add(Stage::Media, move || SousaPass::new(gpu, self.taps, self.resolution, self.brightness));
    }

    fn warnings(&self, flag: &str, manifest: &kiln_format::Manifest, warnings: &mut Vec<String>) {
        no_medium(flag, manifest, warnings);
    }
}
