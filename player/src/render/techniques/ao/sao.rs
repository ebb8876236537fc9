//! `--ao sao`: scalable ambient obscurance as the seed modifies it (seed 000 §2.3,
//! `shaders/sao/sao.comp`): N spiral samples of the camera-space depth pyramid and the G-buffer
//! normals per AO pixel, at full or half resolution, then the screen-space AO's bilateral blur
//! with depth weights that also upsamples ([`ScreenAoPass`]). Deterministic per frame: the AO
//! image is overwritten, never accumulated.

use kiln_format::gpu::ScreenAoConstants;

use super::{AO_RADIUS, Radius, ao_reach};
use crate::render::frame::FrameBuild;
use crate::render::spirv;
use crate::render::techniques::knobs::{UNBOUNDED, choice, number, whole};
use crate::render::techniques::{Knob, Knobs, Registered, ScreenFraction, Technique};

/// The coarsest depth-pyramid level SAO's samples read (`SAO_TOP` in `shaders/sao/sao.comp`;
/// McGuire et al. 2012 stop at 5).
pub const TOP_LEVEL: u32 = 5;

/// Scalable ambient obscurance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sao {
    /// The samples' world radius r.
    pub radius: Radius,
    /// Samples per AO pixel (the seed's N = 16).
    pub samples: u32,
    /// Turns of the sample spiral (τ).
    pub turns: f32,
    /// Full or half resolution (the seed's default: half).
    pub resolution: ScreenFraction,
}

impl Registered for Sao {
    const NAME: &'static str = "sao";
    const HELP: &'static str = "scalable ambient obscurance as seed 000 modifies it: --ao-samples spiral samples of a \
                                camera-space depth pyramid and the G-buffer normals within --ao-radius (or \
                                --ao-reach), at --ao-res, blurred with depth weights; screen space (what the screen \
                                does not show does not occlude)";
    const KNOBS: &'static [Knob] = &[
        AO_RADIUS,
        ao_reach(0.05, &[0.05]),
        whole(number("ao-samples", "samples per AO pixel on the spiral (the seed's N)", 1.0, 64.0, 16.0, &[8.0, 16.0, 32.0])),
        number(
            "ao-turns",
            "turns of the sample spiral (τ; 7: McGuire et al.'s prime for few samples)",
            0.0,
            UNBOUNDED,
            7.0,
            &[],
        ),
        choice(
            "ao-res",
            "resolution of sao's samples: full, or half on each axis (the seed's default), \
             upsampled by the depth-aware blur",
            &["full", "half"],
            1,
        ),
    ];

    fn new(k: &Knobs) -> Result<Sao, String> {
        Ok(Sao {
            radius: Radius::of(k),
            samples: k.whole("ao-samples")?,
            turns: k.number("ao-turns"),
            resolution: ScreenFraction::named(k.choice("ao-res")),
        })
    }
}

impl Technique for Sao {
    super::ao_image!();

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let constants = ScreenAoConstants {
            count: self.samples.max(1),
            turns: self.turns,
            step: self.resolution.divisor(),
            ..Default::default()
        };
        super::screen_ao(frame, TOP_LEVEL, spirv::shader!("sao/sao.comp"), constants, self.radius);
    }
}
