//! Ray-traced ambient occlusion (`shaders/rt/ao.comp`): one cosine-weighted ray per pixel per
//! frame within the AO radius, a hit at t weighing (t/R)², averaged into the AO image
//! ([`super::ao::AO`]).

use super::ao::AO;
use super::hybrid::{self, HybridKernel};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Gpu, ImageDesc, Use};
use crate::render::TexelDecode;
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The ray-traced AO pass.
#[derive(Debug)]
pub struct RtAoPass(HybridKernel);

impl RtAoPass {
    /// Builds the pipeline, decoding the texel buffer as `decode` says.
    pub fn new(gpu: &Gpu, decode: TexelDecode) -> PlayResult<RtAoPass> {
        Ok(RtAoPass(HybridKernel::new(gpu, spirv::shader!("rt/ao.comp"), decode)?))
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
        self.0.bind(gpu, shared)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        self.0.record(ctx, &[(AO, Access::ReadWrite(Use::STORAGE))]);
    }
}
