//! Ray-traced glossy reflections (`shaders/rt/reflections.comp` and
//! `reflection_shadows.comp`): one GGX visible-normal sample per pixel (or per 2 × 2 pixels)
//! weighted F·G2/G1, shaded at the hit; the hits' shadow rays are traced by a second, small
//! kernel (traversal is latency-bound and starves inside the large shading kernel).

use crate::gpu::vk;

use super::hybrid::{self, HybridSet};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{ComputePipeline, Gpu, ImageDesc, Use};
use crate::render::TexelDecode;
use crate::render::graph::{Access, TargetDecl};
use crate::render::{MAX_RT_SHADOW_LIGHTS, spirv};
use kiln_format::gpu::REFLECTION_SECOND_HIT_LIGHTS;

const fn rgba32(name: &'static str, array: bool) -> TargetDecl {
    TargetDecl { name, format: vk::Format::R32G32B32A32_SFLOAT, usage: vk::ImageUsageFlags::STORAGE, array }
}

/// The averaged reflections (rgb, a = 1 where traced), full or half size.
pub const REFLECTIONS: TargetDecl = rgba32("rt reflections", false);
/// Between the kernels: the hit's radiance without the lights' shadowed terms.
pub const PARTIAL: TargetDecl = rgba32("reflection partial", false);
/// Between the kernels: the hits' offset ray origins.
pub const ORIGINS: TargetDecl = rgba32("reflection origins", false);
/// Between the kernels: each light's unshadowed term at the hit, one layer per light, then the
/// same at a metal hit's own reflection's hit for the first [`REFLECTION_SECOND_HIT_LIGHTS`],
/// then that second hit's origin (w = 1 where there is one): [`light_layers`].
pub const LIGHT_TERMS: TargetDecl = rgba32("reflection light terms", true);
/// The pass's targets in binding order (`shaders/rt/hybrid.glsl`, bindings 18–21).
pub const TARGETS: [TargetDecl; 4] = [REFLECTIONS, PARTIAL, ORIGINS, LIGHT_TERMS];

/// Layers of [`LIGHT_TERMS`] for `lights` lights with reflection-hit shadow rays.
pub fn light_layers(lights: u32) -> u32 {
    lights + lights.min(REFLECTION_SECOND_HIT_LIGHTS as u32) + 1
}

/// Lights whose reflection-hit shadow rays are traced.
pub fn lights(lights: usize) -> u32 {
    lights.min(MAX_RT_SHADOW_LIGHTS) as u32
}

/// The reflection pass: trace and shade, then the hits' shadow rays.
#[derive(Debug)]
pub struct RtReflectionsPass {
    trace: ComputePipeline,
    shadows: ComputePipeline,
    set: HybridSet,
    step: u32,
    lights: u32,
}

impl RtReflectionsPass {
    /// Builds the pipelines for one sample per `step` × `step` pixels and a scene of `lights`
    /// lights, decoding the
    /// texel buffer as `decode` says.
    pub fn new(gpu: &Gpu, step: u32, lights: usize, decode: TexelDecode) -> PlayResult<RtReflectionsPass> {
        let set = HybridSet::new(gpu, false, decode)?;
        let trace = set.pipeline(gpu, spirv::shader!("rt/reflections.comp"))?;
        let shadows = set.pipeline(gpu, spirv::shader!("rt/reflection_shadows.comp"))?;
        Ok(RtReflectionsPass { trace, shadows, set, step, lights: self::lights(lights) })
    }
}

impl Pass for RtReflectionsPass {
    fn name(&self) -> &'static str {
        "reflections"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let (w, h) = (width.div_ceil(self.step), height.div_ceil(self.step));
        TARGETS
            .iter()
            .map(|t| (*t, t.sized(w, h, if *t == LIGHT_TERMS { light_layers(self.lights) } else { 1 })))
            .collect()
    }

    fn binds(&self) -> Vec<TargetDecl> {
        hybrid::bound()
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.set.bind(gpu, shared)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let rw = Access::ReadWrite(Use::STORAGE);
        let (w, h) = (ctx.images.width.div_ceil(self.step), ctx.images.height.div_ceil(self.step));
        let groups = [w.div_ceil(8), h.div_ceil(8), 1];
        let push = bytemuck::bytes_of(ctx.rt);
        ctx.images.access(ctx.rec, &hybrid::io(&[(PARTIAL, rw), (ORIGINS, rw), (LIGHT_TERMS, rw)]));
        ctx.rec.dispatch(&self.trace, &[self.set.set], push, groups);
        let read = Access::Read(Use::STORAGE);
        ctx.images
            .access(ctx.rec, &[(PARTIAL, read), (ORIGINS, read), (LIGHT_TERMS, read), (REFLECTIONS, rw)]);
        ctx.rec.dispatch(&self.shadows, &[self.set.set], push, groups);
    }
}
