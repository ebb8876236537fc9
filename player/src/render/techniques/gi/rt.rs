//! `--gi rt`: path traced from the G-buffer through the CWBVH: one cosine-weighted path per
//! pixel per frame, next-event estimation at its hits (`passes/rt_gi.rs`, `shaders/rt/gi.glsl`).


use super::{GI_BOUNCES, GI_REGULARIZE};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::rt_gi::RtGiPass;
use crate::render::spirv;
use crate::render::techniques::{Knob, Knobs, Registered, Technique};

/// Path-traced diffuse GI through the BVH.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rt {
    /// Scattering events after the primary surface whose light counts (1: the sky, and what
    /// the first surface hit emits and receives directly), 1..=8.
    pub bounces: u32,
    /// The least roughness of the surfaces the paths hit (0: unbiased).
    pub regularize: f32,
}

impl Registered for Rt {
    const NAME: &'static str = "rt";
    const HELP: &'static str = "path-traced diffuse GI from the G-buffer through the BVH: one cosine-weighted path per \
                                pixel per frame, next-event estimation to lights and emissive surfaces at its hits, \
                                averaged while the camera is still; replaces the sky's diffuse ambient and its AO \
                                (see --gi-bounces, --gi-regularize)";
    const KNOBS: &'static [Knob] = &[GI_BOUNCES, GI_REGULARIZE];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Rt, String> {
        Ok(Rt { bounces: k.whole("gi-bounces")?, regularize: k.number("gi-regularize") })
    }
}

impl Technique for Rt {
    super::traced_gi!();

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let (gpu, decode) = (frame.gpu, frame.decode);
        frame.add(Stage::Gi, move || RtGiPass::new(gpu, spirv::shader!("rt/gi.comp"), decode));
    }
}
