//! Ray-traced soft shadows (`shaders/rt/shadows.glsl`, seed 001 with its errata fixed): one ray
//! per light per pixel per frame towards a point sampled on the light, averaged into one layer
//! per light; the rays through the BVH (`shadows.comp`) or the binary line space
//! (`shadows_linespace*.comp`, seed 004's shadow feelers).

use crate::gpu::vk;

use super::hybrid::{self, HybridKernel};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Gpu, ImageDesc, Use};
use crate::render::TexelDecode;
use crate::render::graph::{Access, TargetDecl};
use crate::render::technique::{LsShadowTest, Shadows};
use crate::render::{MAX_RT_SHADOW_LIGHTS, spirv};

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
    /// Builds the pipeline of `technique` (its rays through the BVH or the line space) for a
    /// scene of `lights` lights, decoding the texel buffer as `decode` says.
    pub fn new(
        gpu: &Gpu,
        technique: Shadows,
        lights: usize,
        decode: TexelDecode,
    ) -> PlayResult<RtShadowsPass> {
        let kernel = match technique {
            Shadows::LineSpace { test: LsShadowTest::Ends, .. } => {
                HybridKernel::with_line_space(gpu, spirv::RT_SHADOWS_LINESPACE, decode)?
            }
            Shadows::LineSpace { test: LsShadowTest::Filled, .. } => {
                HybridKernel::with_line_space(gpu, spirv::RT_SHADOWS_LINESPACE_EXACT, decode)?
            }
            _ => HybridKernel::new(gpu, spirv::RT_SHADOWS, decode)?,
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

    fn destroy(&mut self, gpu: &Gpu) {
        self.kernel.destroy(gpu);
    }
}
