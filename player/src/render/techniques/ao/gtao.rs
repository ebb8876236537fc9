//! `--ao gtao`: ground-truth ambient occlusion (Jimenez et al. 2016, "Practical Real-Time
//! Strategies for Accurate Indirect Occlusion"; `shaders/gtao/gtao.comp`): per screen pixel,
//! the cosine-weighted visibility integrated over `slices` screen directions, each between the
//! two horizons found by `steps` samples per side of the depth pyramid's level 0 within the
//! world radius, with the normal projected into the slice; then the screen-space AO's bilateral
//! blur ([`ScreenAoPass`]). Full resolution, as Intel's XeGTAO (whose "High" preset is 3 slices
//! × 3 steps, the defaults here). Deterministic per frame.

use kiln_format::gpu::ScreenAoConstants;

use super::{AO_RADIUS, Radius, ao_reach};
use crate::render::frame::FrameBuild;
use crate::render::spirv;
use crate::render::techniques::knobs::{number, whole};
use crate::render::techniques::{Knob, Knobs, Registered, Technique};

/// Ground-truth ambient occlusion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gtao {
    /// The world radius R.
    pub radius: Radius,
    /// Slices (screen directions) per pixel.
    pub slices: u32,
    /// Samples along each side of a slice.
    pub steps: u32,
}

impl Registered for Gtao {
    const NAME: &'static str = "gtao";
    const HELP: &'static str = "ground-truth AO (Jimenez et al. 2016): per pixel, --ao-slices screen directions, each \
                                side's horizon found by --ao-steps samples of the depth pyramid within --ao-radius \
                                (or --ao-reach), the cosine-weighted visibility between the horizons integrated with \
                                the projected normal; blurred with depth weights; screen space";
    const KNOBS: &'static [Knob] = &[
        AO_RADIUS,
        ao_reach(0.05, &[0.05]),
        whole(number("ao-slices", "screen directions per pixel (XeGTAO High: 3)", 1.0, 32.0, 3.0, &[2.0, 3.0, 9.0])),
        whole(number("ao-steps", "samples along each side of a slice (XeGTAO High: 3)", 1.0, 64.0, 3.0, &[2.0, 3.0, 8.0])),
    ];

    fn new(k: &Knobs) -> Result<Gtao, String> {
        Ok(Gtao { radius: Radius::of(k), slices: k.whole("ao-slices")?, steps: k.whole("ao-steps")? })
    }
}

impl Technique for Gtao {
    super::ao_image!();

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let constants =
            ScreenAoConstants { count: self.slices.max(1), steps: self.steps.max(1), step: 1, ..Default::default() };
        // Level 0 only: the horizons are searched at full resolution.
        super::screen_ao(frame, 0, spirv::shader!("gtao/gtao.comp"), constants, self.radius);
    }
}
