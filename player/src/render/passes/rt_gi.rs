//! Diffuse global illumination by path tracing from the G-buffer (`shaders/rt/gi.glsl`): one
//! cosine-weighted path per pixel per frame from the primary surface, with next-event estimation
//! at its hits, averaged into the mean incoming radiance (irradiance / π) that the composition
//! uses in place of the sky's diffuse ambient.
//!
//! The estimator is independent of the ray structure: a kernel defines its hooks (closest hit,
//! shadow rays) and includes it. [`RtGiPass::new`] takes that kernel's SPIR-V; `--gi rt` gives
//! it [`crate::render::spirv::shader!("rt/gi.comp")`], whose hooks trace the CWBVH.

use crate::gpu::vk;

use super::hybrid::{self, HybridKernel};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Gpu, ImageDesc, Use};
use crate::render::TexelDecode;
use crate::render::graph::{Access, TargetDecl};

/// Mean incoming radiance over the cosine-weighted hemisphere of each pixel's surface (rgb).
pub const GI: TargetDecl = TargetDecl {
    name: "rt gi",
    format: vk::Format::R32G32B32A32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The GI pass.
#[derive(Debug)]
pub struct RtGiPass(HybridKernel);

impl RtGiPass {
    /// Builds the pipeline of a GI kernel: `spirv` includes `shaders/rt/gi.glsl` with the hooks
    /// of its ray structure (e.g. [`crate::render::spirv::shader!("rt/gi.comp")`]).
    /// The texel buffer is decoded as `decode` says.
    pub fn new(gpu: &Gpu, spirv: &[u8], decode: TexelDecode) -> PlayResult<RtGiPass> {
        Ok(RtGiPass(HybridKernel::new(gpu, spirv, decode)?))
    }

    /// A GI kernel whose hooks read the line space (`shaders/rt/gi_linespace*.comp`).
    pub fn with_line_space(gpu: &Gpu, spirv: &[u8], decode: TexelDecode) -> PlayResult<RtGiPass> {
        Ok(RtGiPass(HybridKernel::with_line_space(gpu, spirv, decode)?))
    }
}

impl Pass for RtGiPass {
    fn name(&self) -> &'static str {
        "gi"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(GI, GI.sized(width, height, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        hybrid::bound()
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.0.bind(gpu, shared)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        self.0.record(ctx, &[(GI, Access::ReadWrite(Use::STORAGE))]);
    }
}
