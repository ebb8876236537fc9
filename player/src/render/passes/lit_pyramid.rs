//! The lit-radiance pyramid (`shaders/lit/`; seed 000 §3.5, its texture 8): the light that
//! screen-space GI and reflections gather. Level 0 is the previous frame's final radiance
//! reprojected into this frame's pixels (alpha 1 where lit, 0 on the sky and where there is no
//! history); levels 1 to [`super::depth_pyramid::TOP`] are 2 × 2 means of the lit texels, in
//! the depth pyramid's layout (`shaders/common/screen_ao.glsl`), so that a gather reading level
//! k of depth, normals and light reads the same texels of each.
//!
//! Reading the previous frame is what makes the gathered light include indirect light (seed
//! 000's infinite bounces) and costs one frame of lag. A frame without a previous one makes the
//! pyramid again from its own radiance once the direct pass has lit it, and its readers run
//! again ([`crate::render::frame::Frame::again`]): the first frame shows its reflections.

use kiln_format::gpu::ScreenGiConstants;

use super::depth_pyramid::{image_size, levels};
use super::direct::RADIANCE;
use super::gbuffer::DEPTH;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The pyramid's levels in one image (rgb radiance, alpha the lit fraction).
pub const LIT_PYRAMID: TargetDecl = TargetDecl {
    name: "lit pyramid",
    format: vk::Format::R16G16B16A16_SFLOAT,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
    ),
    array: false,
};

/// The pass.
#[derive(Debug)]
pub struct LitPyramidPass {
    reproject: Kernel,
    reduce: Kernel,
}

impl LitPyramidPass {
    /// Builds the pipelines.
    pub fn new(gpu: &Gpu) -> PlayResult<LitPyramidPass> {
        use BindingKind::*;
        let push = std::mem::size_of::<ScreenGiConstants>() as u32;
        let [reproject, reduce] = Kernel::several(
            gpu,
            [
                (
                    &[
                        Binding::one(Uniform),
                        Binding::one(Sampled),
                        Binding::one(StorageImage),
                        Binding::one(StorageImage),
                    ],
                    spirv::shader!("lit/reproject.comp"),
                ),
                (&[Binding::one(Uniform), Binding::one(StorageImage)], spirv::shader!("lit/reduce.comp")),
            ],
            push,
        )?;
        Ok(LitPyramidPass { reproject, reduce })
    }
}

impl Pass for LitPyramidPass {
    fn name(&self) -> &'static str {
        "lit pyramid"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let (w, h) = image_size(width, height);
        vec![(LIT_PYRAMID, LIT_PYRAMID.sized(w, h, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![DEPTH, RADIANCE]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        self.reproject.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Sampled(1, vec![(img(&DEPTH), shared.scene.nearest_clamp)]),
                Write::StorageImage(2, img(&RADIANCE)),
                Write::StorageImage(3, img(&LIT_PYRAMID)),
            ],
        )?;
        self.reduce
            .write(gpu, &[Write::Buffer(0, shared.frame_ubo), Write::StorageImage(1, img(&LIT_PYRAMID))])
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let (width, height) = (ctx.images.width, ctx.images.height);
        ctx.images.access(
            ctx.rec,
            &[
                (DEPTH, Access::Read(Use::SAMPLED)),
                (RADIANCE, Access::Read(Use::STORAGE)),
                (LIT_PYRAMID, Access::Write(Use::STORAGE)),
            ],
        );
        let level0 = ScreenGiConstants { current: ctx.again as u32, ..Default::default() };
        self.reproject.dispatch(ctx.rec, bytemuck::bytes_of(&level0), width, height);
        for (level, &(w, h)) in levels(width, height).iter().enumerate().skip(1) {
            // Each level reads the one the previous dispatch wrote.
            ctx.images.access(ctx.rec, &[(LIT_PYRAMID, Access::ReadWrite(Use::STORAGE))]);
            let push = ScreenGiConstants { level: level as u32, ..Default::default() };
            self.reduce.dispatch(ctx.rec, bytemuck::bytes_of(&push), w, h);
        }
    }
}
