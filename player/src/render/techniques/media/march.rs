//! `--media march`: single scattering by marching each pixel's view ray through the media in
//! world space: light visibility from the baked volume (trilinear), transmittance analytic, the
//! sky's light from the baked sky grids (format 1.10) times the sky convolved with the phase
//! function (`passes/media.rs`, `shaders/media/march.comp`).

use super::{casters, no_medium};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::media::MediaMarchPass;
use crate::render::techniques::knobs::{number, whole};
use crate::render::techniques::{Knob, Knobs, Needs, Registered, Technique};

/// Single scattering by ray marching.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct March {
    /// Steps through each medium the ray crosses.
    pub steps: u32,
}

impl Registered for March {
    const NAME: &'static str = "march";
    const HELP: &'static str = "single scattering: each pixel's view ray marched through the media in world space \
                                (light visibility from the compiler's baked volume, transmittance analytic; works \
                                with the light off screen; the sky's light too, where the file has the sky's grids), \
                                see --media-steps";
    const KNOBS: &'static [Knob] = &[whole(number(
        "media-steps",
        "steps along the view ray through each medium",
        1.0,
        1024.0,
        32.0,
        &[8.0, 16.0, 32.0, 64.0],
    ))];

    fn new(k: &Knobs) -> Result<March, String> {
        Ok(March { steps: k.whole("media-steps")? })
    }
}

impl Technique for March {
    fn needs(&self) -> Needs {
        Needs { media: true, media_volumes: true, ..Needs::NONE }
    }

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let gpu = frame.gpu;
        frame.add(Stage::Media, move || MediaMarchPass::new(gpu, self.steps));
    }

    fn dims_surfaces(&self) -> bool {
        true
    }

    fn warnings(&self, flag: &str, manifest: &kiln_format::Manifest, warnings: &mut Vec<String>) {
        if !no_medium(flag, manifest, warnings) && manifest.media_visibility.is_none() && casters(manifest) {
            warnings.push(format!("{flag}: the file has no light-visibility volume; shafts of light are unshadowed"));
        }
    }
}
