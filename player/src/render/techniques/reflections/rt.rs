//! `--reflections rt`: one GGX visible-normal sample per pixel (or per 2 × 2) per frame through
//! the BVH, shaded at the hit (`passes/rt_reflections.rs`, `shaders/rt/reflections.comp`): its
//! lights, each with one shadow ray, and the irradiance probes' light where the file has them,
//! else the sky's.

use kiln_format::gpu::FrameFlags;

use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::rt_history::{Accumulated, Kind};
use crate::render::passes::rt_reflections::{self, RtReflectionsPass};
use crate::render::techniques::knobs::{UNBOUNDED, choice, number};
use crate::render::techniques::{Knob, Knobs, Needs, RayInputs, RayScene, Registered, Technique};

/// Ray-traced glossy reflections.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rt {
    /// Full or half resolution.
    pub resolution: ReflectionRes,
    /// Surfaces rougher than this keep the split-sum ambient.
    pub max_roughness: f32,
    /// Metal hits smoother than this trace their own reflection one bounce further (0: none).
    pub metal_bounce: f32,
}

/// The default of `--reflection-metal-bounce`: metal hits smoother than this reflect by one
/// more traced ray. pica_pica's aluminium (roughness 0.23) is under it; at 1.0 every metal hit
/// would be traced, for the same error there (docs/benchmarks/metal-bounce/).
pub const METAL_BOUNCE: f32 = 0.6;

/// Resolution of the ray-traced reflections.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReflectionRes {
    /// One ray per pixel.
    Full,
    /// One ray per 2 × 2 pixels, upsampled with normal- and plane-aware weights.
    Half,
}

impl ReflectionRes {
    /// Pixels per reflection sample along each axis.
    pub fn step(self) -> u32 {
        match self {
            ReflectionRes::Full => 1,
            ReflectionRes::Half => 2,
        }
    }
}

impl Registered for Rt {
    const NAME: &'static str = "rt";
    const HELP: &'static str = "ray-traced glossy reflections (GGX visible-normal samples, one per pixel per frame \
                                at --reflection-res); the hits lit by their lights and by the compiler's \
                                irradiance probes where the file has them (the sky's light where not)";
    const KNOBS: &'static [Knob] = &[
        choice(
            "reflection-res",
            "full: one ray per pixel; half: one per 2 × 2 pixels, upsampled with edge-aware weights",
            &["full", "half"],
            0,
        ),
        number(
            "reflection-max-roughness",
            "surfaces rougher than this keep the split-sum ambient",
            0.0,
            UNBOUNDED,
            1.0,
            &[0.4, 1.0],
        ),
        number(
            "reflection-metal-bounce",
            "metal that a reflection ray hits, where smoother than this, reflects by one more traced ray \
             (metal seen in metal: a console's deck mirroring its panel, which mirrors the room) instead of \
             the probes' or the sky's light about its mirror direction (0: never)",
            0.0,
            1.0,
            METAL_BOUNCE,
            &[0.0, METAL_BOUNCE],
        ),
    ];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Rt, String> {
        Ok(Rt {
            resolution: if k.choice("reflection-res") == "half" { ReflectionRes::Half } else { ReflectionRes::Full },
            max_roughness: k.number("reflection-max-roughness"),
            metal_bounce: k.number("reflection-metal-bounce"),
        })
    }
}

impl Technique for Rt {
    fn ray_traced(&self) -> bool {
        true
    }

    /// The probes light the hits where the file has them (`shaders/rt/reflections.comp`).
    fn needs(&self) -> Needs {
        Needs { probes_if_present: true, ..Needs::NONE }
    }

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let (gpu, lights, decode) = (frame.gpu, frame.scene.lights, frame.decode);
        frame.add(Stage::Reflections, move || RtReflectionsPass::new(gpu, self.resolution.step(), lights, decode));
    }

    fn flags(&self) -> u32 {
        match self.resolution {
            ReflectionRes::Full => FrameFlags::RT_REFLECTIONS,
            ReflectionRes::Half => FrameFlags::RT_REFLECTIONS | FrameFlags::REFLECTIONS_HALF,
        }
    }

    fn accumulated(&self, _: usize) -> Option<Accumulated> {
        let histories = ["rt reflections history a", "rt reflections history b"];
        let step = self.resolution.step();
        Some(Accumulated::new(rt_reflections::REFLECTIONS, histories, Kind::Four, step, 1))
    }

    fn rays(&self, scene: &RayScene, inputs: &mut RayInputs) {
        inputs.rt.reflection_step = self.resolution.step();
        inputs.rt.reflection_lights = rt_reflections::lights(scene.lights_used);
        inputs.rt.max_roughness = self.max_roughness;
        inputs.rt.metal_bounce_roughness = self.metal_bounce;
    }
}
