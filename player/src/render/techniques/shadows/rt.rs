//! `--shadows rt`: one ray per light per pixel per frame towards a point sampled on the light,
//! through the BVH (`passes/rt_shadows.rs`, `shaders/rt/shadows.comp`).

use kiln_format::gpu::FrameFlags;

use super::{LIGHT_RADIUS, SUN_ANGLE, traced_fallback, traced_rays};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::rt_history::Accumulated;
use crate::render::passes::rt_shadows::RtShadowsPass;
use crate::render::spirv;
use crate::render::techniques::{Knob, Knobs, RayInputs, RayScene, Registered, Technique};

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
    fn ray_traced(&self) -> bool {
        true
    }

    fn fallback(&self, shadow_maps: bool) -> Option<&'static str> {
        traced_fallback(shadow_maps)
    }

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let (gpu, lights, decode) = (frame.gpu, frame.lights.count, frame.decode);
        frame.add(Stage::Shadows, move || RtShadowsPass::new(gpu, spirv::shader!("rt/shadows.comp"), false, lights, decode));
    }

    fn flags(&self) -> u32 {
        FrameFlags::RT_SHADOWS
    }

    fn accumulated(&self, lights: usize) -> Option<Accumulated> {
        super::accumulated(lights)
    }

    fn rays(&self, scene: &RayScene, inputs: &mut RayInputs) {
        traced_rays(self.light_radius, self.sun_degrees, scene, inputs);
    }
}
