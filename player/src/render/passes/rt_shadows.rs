//! Ray-traced soft shadows (`shaders/rt/shadows.glsl`, seed 001 with its errata fixed): one ray
//! per light per pixel per frame towards a point sampled on the light, averaged into one layer
//! per light; the rays through the BVH (`shadows.comp`) or the binary line space
//! (`shadows_linespace*.comp`, seed 004's shadow feelers).

use crate::gpu::vk;

use super::hybrid::{self, HybridKernel};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Gpu, ImageDesc, Use};
use crate::render::MAX_RT_SHADOW_LIGHTS;
use crate::render::TexelDecode;
use crate::render::graph::{Access, TargetDecl};

/// Shadow visibility, one layer per light.
pub const SHADOWS: TargetDecl = TargetDecl {
    name: "rt shadows",
    format: vk::Format::R32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: true,
};

/// Layers of [`SHADOWS`] for a scene of `lights` lights (one at least).
pub fn layers(lights: usize) -> u32 {
    lights.clamp(1, MAX_RT_SHADOW_LIGHTS) as u32
}

/// The ray-traced shadow pass.
#[derive(Debug)]
pub struct RtShadowsPass {
    kernel: HybridKernel,
    layers: u32,
}

impl RtShadowsPass {
    /// Builds the pipeline of the shader `code` (its rays through the BVH, or through the line
    /// space when `line_space`) for a scene of `lights` lights, decoding the texel buffer as
    /// `decode` says.
    pub fn new(
        gpu: &Gpu,
        code: &[u8],
        line_space: bool,
        lights: usize,
        decode: TexelDecode,
    ) -> PlayResult<RtShadowsPass> {
        let kernel = if line_space {
            HybridKernel::with_line_space(gpu, code, decode)?
        } else {
            HybridKernel::new(gpu, code, decode)?
        };
        Ok(RtShadowsPass { kernel, layers: layers(lights) })
    }
}

impl Pass for RtShadowsPass {
    fn name(&self) -> &'static str {
        "shadows"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(SHADOWS, SHADOWS.sized(width, height, self.layers))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        hybrid::bound()
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.kernel.bind(gpu, shared)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        self.kernel.record(ctx, &[(SHADOWS, Access::ReadWrite(Use::STORAGE))]);
    }
}
