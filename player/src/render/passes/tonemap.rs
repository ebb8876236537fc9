//! Tone mapping (`shaders/post/tonemap.comp`): display = sRGB(ACES(2^EV · radiance)), with
//! Narkowicz's fit of the ACES filmic curve, per channel.

use crate::gpu::vk;

use super::direct::RADIANCE;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The tone-mapped image (sRGB-encoded values in a UNORM image).
pub const DISPLAY: TargetDecl = TargetDecl {
    name: "display",
    format: vk::Format::R8G8B8A8_UNORM,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::TRANSFER_SRC.as_raw(),
    ),
    array: false,
};

/// The tone-mapping pass.
#[derive(Debug)]
pub struct TonemapPass(Kernel);

impl TonemapPass {
    /// Builds the pipeline.
    pub fn new(gpu: &Gpu) -> PlayResult<TonemapPass> {
        use BindingKind::*;
        let bindings = [Binding::one(Uniform), Binding::one(StorageImage), Binding::one(StorageImage)];
        Ok(TonemapPass(Kernel::new(gpu, &bindings, spirv::shader!("post/tonemap.comp"), 0)?))
    }
}

impl Pass for TonemapPass {
    fn name(&self) -> &'static str {
        "tonemap"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(DISPLAY, DISPLAY.sized(width, height, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![RADIANCE]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        self.0.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::StorageImage(1, img(&RADIANCE)),
                Write::StorageImage(2, img(&DISPLAY)),
            ],
        )
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        ctx.images.access(
            ctx.rec,
            &[(RADIANCE, Access::Read(Use::STORAGE)), (DISPLAY, Access::Write(Use::STORAGE))],
        );
        self.0.dispatch(ctx.rec, &[], ctx.images.width, ctx.images.height);
    }
}
