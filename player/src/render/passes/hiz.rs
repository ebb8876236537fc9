//! The Hi-Z pyramid of the screen-space reflections (`shaders/hiz/`): the closest surface under
//! every cell, the conservative bound a hierarchical ray march skips empty space with
//! ([`super::ssr`]).
//!
//! Level 0 is the G-buffer's reversed-Z depth unchanged (0 where the sky shows); levels 1 to
//! [`TOP`] halve each side, rounding up, each texel the **largest** depth (the closest surface) of
//! its 2 × 2 children. Rounding up makes every child's parent child / 2, so that the last texel of
//! an odd-sized level covers the one or two children that exist, and no surface is left out of a
//! coarser cell. The depth pyramid of the screen-space AO ([`super::depth_pyramid`]) keeps one
//! child unchanged instead (nearest), which a march cannot skip by.
//!
//! All levels live in one `r32f` image in the depth pyramid's layout (level 0 at the origin,
//! levels 1.. in a column to its right; `pyramid_origin` in `shaders/common/screen_ao.glsl`), with
//! more levels: a march climbs as high as the empty space allows. Each level's dispatch declares
//! the image read-written, so that the graph orders it after the level it reads.

use kiln_format::gpu::SsrConstants;

use super::depth_pyramid;
use super::gbuffer::DEPTH;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The coarsest level (`MAX_LEVELS − 1` in `shaders/ssr/trace.comp`): at 1920 × 1080 its cells
/// are 256 pixels wide, 8 × 5 of them.
pub const TOP: u32 = 8;

/// The pyramid's levels in one image.
pub const HIZ: TargetDecl = TargetDecl {
    name: "hi-z",
    format: vk::Format::R32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The size of every level, 0 to [`TOP`], for a `width` × `height` screen (the layout of the
/// depth pyramid's atlas, two levels deeper).
pub fn levels(width: u32, height: u32) -> Vec<(u32, u32)> {
    depth_pyramid::levels_up_to(width, height, TOP)
}

/// The image holding all levels.
pub fn image_size(width: u32, height: u32) -> (u32, u32) {
    depth_pyramid::atlas_size(width, height, TOP)
}

/// The pass.
#[derive(Debug)]
pub struct HizPass {
    copy: Kernel,
    reduce: Kernel,
}

impl HizPass {
    /// Builds the pipelines.
    pub fn new(gpu: &Gpu) -> PlayResult<HizPass> {
        use BindingKind::*;
        let push = std::mem::size_of::<SsrConstants>() as u32;
        let [copy, reduce] = Kernel::several(
            gpu,
            [
                (
                    &[Binding::one(Uniform), Binding::one(Sampled), Binding::one(StorageImage)],
                    spirv::shader!("hiz/copy.comp"),
                ),
                (&[Binding::one(Uniform), Binding::one(StorageImage)], spirv::shader!("hiz/reduce.comp")),
            ],
            push,
        )?;
        Ok(HizPass { copy, reduce })
    }
}

impl Pass for HizPass {
    fn name(&self) -> &'static str {
        "hi-z"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let (w, h) = image_size(width, height);
        vec![(HIZ, HIZ.sized(w, h, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![DEPTH]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        self.copy.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Sampled(1, vec![(img(&DEPTH), shared.scene.nearest_clamp)]),
                Write::StorageImage(2, img(&HIZ)),
            ],
        )?;
        self.reduce.write(gpu, &[Write::Buffer(0, shared.frame_ubo), Write::StorageImage(1, img(&HIZ))])
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let (width, height) = (ctx.images.width, ctx.images.height);
        ctx.images
            .access(ctx.rec, &[(DEPTH, Access::Read(Use::SAMPLED)), (HIZ, Access::Write(Use::STORAGE))]);
        let push = SsrConstants { top: TOP, ..Default::default() };
        self.copy.dispatch(ctx.rec, bytemuck::bytes_of(&push), width, height);
        for (level, &(w, h)) in levels(width, height).iter().enumerate().skip(1) {
            // Reads the level below, written by the previous dispatch: a barrier between them.
            ctx.images.access(ctx.rec, &[(HIZ, Access::ReadWrite(Use::STORAGE))]);
            let push = SsrConstants { level: level as u32, top: TOP, ..Default::default() };
            self.reduce.dispatch(ctx.rec, bytemuck::bytes_of(&push), w, h);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_halve_rounding_up_down_to_one_texel_and_fit_in_the_image() {
        assert_eq!(levels(96, 72)[..4], [(96, 72), (48, 36), (24, 18), (12, 9)]);
        assert_eq!(levels(96, 72)[TOP as usize], (1, 1));
        // 36 + 18 + 9 + 5 + 3 + 2 + 1 + 1 = 75 > 72: the column sets the height.
        assert_eq!(image_size(96, 72), (144, 75));
        // Every child's parent is child / 2: an odd level's last texel has a parent.
        for (below, above) in levels(1919, 1079).windows(2).map(|w| (w[0], w[1])) {
            assert_eq!(((below.0 - 1) / 2 + 1, (below.1 - 1) / 2 + 1), above);
        }
    }
}
