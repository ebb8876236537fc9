//! Fast approximate anti-aliasing (`--aa fxaa`, `shaders/fxaa/`): the composed radiance's edges
//! found and blended by the pixels' estimated coverage into an image of their own
//! (`fxaa.comp`), which is then written over the radiance (`copy.comp`), so that tone mapping,
//! read-back and the next frame's lit pyramid see the smoothed image.

use kiln_format::gpu::FxaaConstants;

use super::direct::RADIANCE;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The smoothed radiance, before it is copied back.
pub const SMOOTHED: TargetDecl = TargetDecl {
    name: "fxaa smoothed",
    format: vk::Format::R32G32B32A32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// Lottes's "quality" edge thresholds (FXAA 3.11's defaults): an edge where the local contrast
/// of perceptual luma exceeds an eighth of the brightest neighbour's, and 1/32 in the dark.
const THRESHOLD: f32 = 0.125;
const THRESHOLD_MIN: f32 = 0.0312;

/// The pass.
#[derive(Debug)]
pub struct FxaaPass {
    smooth: Kernel,
    copy: Kernel,
    constants: FxaaConstants,
}

impl FxaaPass {
    /// Builds the pipelines, blending single-pixel features by `subpix` (0 to 1).
    pub fn new(gpu: &Gpu, subpix: f32) -> PlayResult<FxaaPass> {
        use BindingKind::*;
        let bindings = [Binding::one(Uniform), Binding::one(StorageImage), Binding::one(StorageImage)];
        let [smooth, copy] = Kernel::several(
            gpu,
            [(&bindings, spirv::shader!("fxaa/fxaa.comp")), (&bindings, spirv::shader!("fxaa/copy.comp"))],
            std::mem::size_of::<FxaaConstants>() as u32,
        )?;
        let constants = FxaaConstants {
            subpix: subpix.clamp(0.0, 1.0),
            threshold: THRESHOLD,
            threshold_min: THRESHOLD_MIN,
            pad: 0,
        };
        Ok(FxaaPass { smooth, copy, constants })
    }
}

impl Pass for FxaaPass {
    fn name(&self) -> &'static str {
        "fxaa"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(SMOOTHED, SMOOTHED.sized(width, height, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![RADIANCE]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        // Each kernel reads one image and writes the other.
        let io = |from: &TargetDecl, to: &TargetDecl| {
            [
                Write::Buffer(0, shared.frame_ubo),
                Write::StorageImage(1, img(from)),
                Write::StorageImage(2, img(to)),
            ]
        };
        self.smooth.write(gpu, &io(&RADIANCE, &SMOOTHED))?;
        self.copy.write(gpu, &io(&SMOOTHED, &RADIANCE))
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let (width, height) = (ctx.images.width, ctx.images.height);
        let push = bytemuck::bytes_of(&self.constants);
        ctx.images.access(
            ctx.rec,
            &[(RADIANCE, Access::Read(Use::STORAGE)), (SMOOTHED, Access::Write(Use::STORAGE))],
        );
        self.smooth.dispatch(ctx.rec, push, width, height);
        ctx.images.access(
            ctx.rec,
            &[(SMOOTHED, Access::Read(Use::STORAGE)), (RADIANCE, Access::Write(Use::STORAGE))],
        );
        self.copy.dispatch(ctx.rec, push, width, height);
    }
}
