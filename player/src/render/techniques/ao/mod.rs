//! Ambient occlusion: the image the direct-light pass multiplies the sky's ambient by.

use super::knobs::{Knob, UNBOUNDED, number};
use kiln_format::gpu::ScreenAoConstants;

use super::techniques;
use crate::render::frame::{FrameBuild, Stage};
pub use crate::render::passes::ao::Radius;
use crate::render::passes::ao::ScreenAoPass;
use crate::render::passes::depth_pyramid::Reduction;

techniques! {
    /// Ambient occlusion.
    Ao for Ao, default none::Off;
    none => Off,
    rt => Rt,
    sao => Sao,
    gtao => Gtao,
}

/// The AO radius in scene units, for every AO technique.
pub const AO_RADIUS: Knob = number(
    "ao-radius",
    "AO radius in scene units (rt: the ray length; sao, gtao: the world radius of the samples); \
     0: --ao-reach times the scene's diagonal",
    0.0,
    UNBOUNDED,
    0.0,
    &[0.0],
);

/// The AO radius as a fraction of the scene's diagonal, with a technique's default and sweep.
pub const fn ao_reach(default: f32, sweep: &'static [f32]) -> Knob {
    number(
        "ao-reach",
        "AO radius as a fraction of the scene's bounding-box diagonal, when --ao-radius is 0 (rt: \
         0.1, ≥ 10 makes every hit occlude fully, the sky's true visibility; sao, gtao: 0.05, about \
         the seed's 1.8 m in Sponza's 40 m)",
        1e-4,
        UNBOUNDED,
        default,
        sweep,
    )
}

/// Adds a screen-space AO technique's pass: the depth pyramid up to level `top` (nearest), then
/// the estimator `code` with `constants` and the shared depth-aware blur, at world radius
/// `radius`.
fn screen_ao(
    frame: &mut FrameBuild<'_>,
    top: u32,
    code: &'static [u8],
    constants: ScreenAoConstants,
    radius: Radius,
) {
    frame.depth_pyramid(Reduction::Nearest, false, top);
    let gpu = frame.gpu;
    frame.add(Stage::Ao, move || ScreenAoPass::new(gpu, code, constants, radius));
}

/// The `Technique` methods every AO technique shares (its settings' `radius`): the direct pass
/// multiplies the sky's ambient by the AO image (`RT_AO`, named before the screen-space
/// techniques came), and the ray-traced passes' constants hold the world radius.
macro_rules! ao_image {
    () => {
        fn flags(&self) -> u32 {
            kiln_format::gpu::FrameFlags::RT_AO
        }

        fn rays(
            &self,
            scene: &$crate::render::techniques::RayScene,
            inputs: &mut $crate::render::techniques::RayInputs,
        ) {
            inputs.rt.ao_radius = self.radius.world(scene.diagonal).max(1e-6);
        }
    };
}
use ao_image;

impl Radius {
    /// The radius of the knobs `ao-radius` (0: none) and `ao-reach`.
    pub fn of(k: &super::Knobs) -> Radius {
        let r = k.number("ao-radius");
        Radius { radius: (r > 0.0).then_some(r), reach: k.number("ao-reach") }
    }
}
