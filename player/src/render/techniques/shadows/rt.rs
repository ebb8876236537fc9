//! `--shadows rt`: one ray per light per pixel per frame towards a point sampled on the light,
//! through the BVH (`passes/rt_shadows.rs`, `shaders/rt/shadows.comp`).


use super::{LIGHT_RADIUS, SUN_ANGLE};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::rt_shadows::RtShadowsPass;
use crate::render::spirv;
use crate::render::techniques::{Knob, Knobs, Registered, Technique};

/// Ray-traced soft shadows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rt {
    /// Sphere radius of point and spot lights in scene units (0: hard shadows).
    pub light_radius: f32,
    /// Angular diameter of directional lights in degrees (0: hard).
    pub sun_degrees: f32,
}

impl Registered for Rt {
    const NAME: &'static str = "rt";
    const HELP: &'static str = "ray-traced soft shadows: one ray per light per pixel per frame, averaged while the \
                                camera is still (see --light-radius, --sun-angle)";
    const KNOBS: &'static [Knob] = &[LIGHT_RADIUS, SUN_ANGLE];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Rt, String> {
        Ok(Rt { light_radius: k.number("light-radius"), sun_degrees: k.number("sun-angle") })
    }
}

impl Technique for Rt {
    super::traced_shadows!();


    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let (gpu, lights, decode) = (frame.gpu, frame.scene.lights, frame.decode);
        frame.add(Stage::Shadows, move || RtShadowsPass::new(gpu, spirv::shader!("rt/shadows.comp"), false, lights, decode));
    }
}
