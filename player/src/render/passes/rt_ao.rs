//! Ray-traced ambient occlusion (`shaders/rt/ao.comp`): one cosine-weighted ray per pixel per
//! frame within the AO radius, a hit at t weighing (t/R)², averaged.

use crate::gpu::vk;

use super::hybrid::{self, HybridSet};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{ComputePipeline, Gpu, ImageDesc, Use};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// Ambient openness.
pub const AO: TargetDecl = TargetDecl {
    name: "rt ao",
    format: vk::Format::R32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The ray-traced AO pass.
#[derive(Debug)]
pub struct RtAoPass {
    set: HybridSet,
    pipeline: ComputePipeline,
}

impl RtAoPass {
    /// Builds the pipeline.
    pub fn new(gpu: &Gpu) -> PlayResult<RtAoPass> {
        let mut set = HybridSet::new(gpu)?;
        match set.pipeline(gpu, spirv::RT_AO) {
            Ok(pipeline) => Ok(RtAoPass { set, pipeline }),
            Err(e) => {
                set.destroy(gpu);
                Err(e)
            }
        }
    }
}

impl Pass for RtAoPass {
    fn name(&self) -> &'static str {
        "ao"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(AO, AO.sized(width, height, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        hybrid::bound()
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.set.bind(gpu, shared)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        ctx.images.access(ctx.rec, &hybrid::io(&[(AO, Access::ReadWrite(Use::STORAGE))]));
        let (w, h) = (ctx.images.width, ctx.images.height);
        let push = bytemuck::bytes_of(ctx.rt);
        ctx.rec.dispatch(&self.pipeline, &[self.set.set], push, [w.div_ceil(8), h.div_ceil(8), 1]);
    }

    fn destroy(&mut self, gpu: &Gpu) {
        self.pipeline.destroy(gpu);
        self.set.destroy(gpu);
    }
}
