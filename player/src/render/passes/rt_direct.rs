//! Direct light of emissive surfaces (`shaders/rt/direct.glsl`): per pixel, candidates on the
//! emissive triangles chosen by resampled importance sampling, reservoirs reused across frames
//! and neighbours (ReSTIR DI), one shadow ray for the sample that shades. Two kernels over the
//! hybrid table: the candidates (and the previous frame's reservoir), then the neighbours and
//! the shading. The composition adds the light they leave in [`DIRECT`]. Their shadow rays go
//! through the BVH, or through the line space with `--shadows linespace` ([`Visibility`]).

use crate::gpu::vk;

use super::hybrid::{self, HybridSet};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{ComputePipeline, Gpu, ImageDesc, Use};
use crate::render::TexelDecode;
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

const fn storage(name: &'static str, format: vk::Format) -> TargetDecl {
    TargetDecl { name, format, usage: vk::ImageUsageFlags::STORAGE, array: false }
}

/// The emissive triangles' light reflected towards the camera at each pixel (rgb).
pub const DIRECT: TargetDecl = storage("rt direct", vk::Format::R32G32B32A32_SFLOAT);
/// Each pixel's reservoir as the last frame left it (the shading kernel writes it).
pub const RESERVOIRS_THEN: TargetDecl = storage("direct reservoirs then", vk::Format::R32G32B32A32_UINT);
/// Each pixel's reservoir after its candidates and the previous frame's (the candidates kernel
/// writes it, the shading kernel reads it at neighbours).
pub const RESERVOIRS_NOW: TargetDecl = storage("direct reservoirs now", vk::Format::R32G32B32A32_UINT);
/// The surface each kept reservoir was made at.
pub const SURFACES_THEN: TargetDecl = storage("direct surfaces then", vk::Format::R32G32B32A32_SFLOAT);
/// Every target, in binding order (26–29).
pub const TARGETS: [TargetDecl; 4] = [DIRECT, RESERVOIRS_THEN, RESERVOIRS_NOW, SURFACES_THEN];

/// The direct-light pass of emissive surfaces.
#[derive(Debug)]
pub struct RtDirectPass {
    candidates: ComputePipeline,
    reuse: ComputePipeline,
    set: HybridSet,
}

/// What the shadow rays go through: the shadows technique's structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Visibility {
    /// The BVH (`--shadows rt`, and `shadowmap`, whose maps are the analytic lights' only).
    Bvh,
    /// The binary line space (`--shadows linespace`), exact in every filled shaft or only in
    /// the cells at the rays' ends.
    LineSpace {
        /// Exact triangle tests in every filled shaft.
        exact: bool,
    },
}

impl RtDirectPass {
    /// Builds both kernels, their shadow rays through `visibility`; the texel buffer is decoded
    /// as `decode` says.
    pub fn new(gpu: &Gpu, decode: TexelDecode, visibility: Visibility) -> PlayResult<RtDirectPass> {
        let (candidates, reuse) = match visibility {
            Visibility::Bvh => {
                (spirv::shader!("rt/direct_candidates.comp"), spirv::shader!("rt/direct_reuse.comp"))
            }
            Visibility::LineSpace { exact: false } => (
                spirv::shader!("rt/direct_candidates_linespace.comp"),
                spirv::shader!("rt/direct_reuse_linespace.comp"),
            ),
            Visibility::LineSpace { exact: true } => (
                spirv::shader!("rt/direct_candidates_linespace_exact.comp"),
                spirv::shader!("rt/direct_reuse_linespace_exact.comp"),
            ),
        };
        let set = HybridSet::new(gpu, matches!(visibility, Visibility::LineSpace { .. }), decode)?;
        let candidates = set.pipeline(gpu, candidates)?;
        let reuse = set.pipeline(gpu, reuse)?;
        Ok(RtDirectPass { candidates, reuse, set })
    }
}

impl Pass for RtDirectPass {
    fn name(&self) -> &'static str {
        "direct emitters"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        TARGETS.iter().map(|t| (*t, t.sized(width, height, 1))).collect()
    }

    fn binds(&self) -> Vec<TargetDecl> {
        hybrid::bound()
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.set.bind(gpu, shared)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let (rw, read) = (Access::ReadWrite(Use::STORAGE), Access::Read(Use::STORAGE));
        let groups = [ctx.images.width.div_ceil(8), ctx.images.height.div_ceil(8), 1];
        let push = bytemuck::bytes_of(ctx.rt);
        ctx.images.access(
            ctx.rec,
            &hybrid::io(&[(RESERVOIRS_THEN, read), (SURFACES_THEN, read), (RESERVOIRS_NOW, rw)]),
        );
        ctx.rec.dispatch(&self.candidates, &[self.set.set], push, groups);
        ctx.images.access(
            ctx.rec,
            &[(RESERVOIRS_NOW, read), (RESERVOIRS_THEN, rw), (SURFACES_THEN, rw), (DIRECT, rw)],
        );
        ctx.rec.dispatch(&self.reuse, &[self.set.set], push, groups);
    }
}
