//! `--media mitchell`: Mitchell's god rays (seed 002): a radial blur of an occlusion image
//! towards each light's screen position (`passes/mitchell.rs`, `shaders/mitchell/`). Image
//! space: no shafts from a light behind the camera.

use super::{MEDIA_RES, MEDIA_SAMPLES, no_medium};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::mitchell::MitchellPass;
use crate::render::techniques::knobs::{UNBOUNDED, number, scene};
use crate::render::techniques::{Knob, Knobs, Needs, Registered, ScreenFraction, Technique};

/// Mitchell's god rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mitchell {
    /// Samples towards the light (the seed's n).
    pub samples: u32,
    /// Resolution of the occlusion image.
    pub resolution: ScreenFraction,
    /// The gain of a march that sees the emitter at every sample (the seed's exposure × n).
    pub exposure: f32,
}

impl Registered for Mitchell {
    const NAME: &'static str = "mitchell";
    const HELP: &'static str = "Mitchell's god rays (seed 002): each light's emitter (the sky for a directional \
                                light, its rectangle for a rect light, a small sphere for point and spot lights) \
                                blurred radially towards its screen position; image space, so no shafts from a light behind the camera or from what \
                                the screen does not show; see --media-samples, --media-res, --media-exposure";
    const KNOBS: &'static [Knob] = &[
        MEDIA_SAMPLES,
        MEDIA_RES,
        // Artistic: a sweep holds it at its default.
        scene(number(
            "media-exposure",
            "the shafts' gain where every sample sees the emitter (the seed's exposure × n)",
            0.0,
            UNBOUNDED,
            1.921,
            &[],
        )),
    ];

    fn new(k: &Knobs) -> Result<Mitchell, String> {
        Ok(Mitchell {
            samples: k.whole("media-samples")?,
            resolution: ScreenFraction::named(k.choice("media-res")),
            exposure: k.number("media-exposure"),
        })
    }
}

impl Technique for Mitchell {
    fn needs(&self) -> Needs {
        Needs { media: true, ..Needs::NONE }
    }

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let gpu = frame.gpu;
        frame.add(Stage::Media, move || MitchellPass::new(gpu, self.samples, self.resolution, self.exposure));
    }

    fn warnings(&self, flag: &str, manifest: &kiln_format::Manifest, warnings: &mut Vec<String>) {
        no_medium(flag, manifest, warnings);
    }
}
