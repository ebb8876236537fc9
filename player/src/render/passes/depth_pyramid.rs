//! The camera-space depth pyramid (`shaders/pyramid/`), for the screen-space passes that read
//! depth over large radii (SAO's per-sample MIP level; later SSGI, SSR's Hi-Z).
//!
//! Level 0 is each pixel's distance along the camera's forward axis, from the reversed-Z depth
//! (0 where the sky shows); levels 1 to [`TOP`] halve each side (rounded up). The reduction is
//! **nearest**: a level's pixel copies one of its 2 × 2 children unchanged, picked on McGuire
//! et al.'s rotated grid (2012, §2.2: child (1 − y mod 2, 1 − x mod 2)), so that no level
//! invents a depth between two surfaces (an average would, at every silhouette) and successive
//! levels do not all keep the same corner. The seed's voting filter (seed 000 §3.8: the child
//! whose depth and normal agree best with the 4 × 4 neighbourhood's means) is not implemented;
//! it needs the normals pyramid too and buys temporal stability, not correctness.
//!
//! All levels live in one `r32f` image (level 0 at the origin, levels 1.. in a column to its
//! right; `shaders/common/screen_ao.glsl` spells the layout), so the graph tracks one image.
//! Each level's dispatch declares the image read-written: the graph then puts a barrier
//! (storage write → storage read/write, whole image) between consecutive levels, which orders
//! every level after the one it reads. Coarser than per-level barriers, but sound and cheap at
//! six dispatches.

use kiln_format::gpu::ScreenAoConstants;

use super::gbuffer::DEPTH;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The coarsest level (`PYRAMID_TOP` in `shaders/common/screen_ao.glsl`).
pub const TOP: u32 = 5;

/// The pyramid's levels in one image.
pub const PYRAMID: TargetDecl = TargetDecl {
    name: "depth pyramid",
    format: vk::Format::R32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The size of every level, 0 to [`TOP`], for a `width` × `height` screen.
pub fn levels(width: u32, height: u32) -> Vec<(u32, u32)> {
    let mut s = (width.max(1), height.max(1));
    let mut out = vec![s];
    for _ in 0..TOP {
        s = (s.0.div_ceil(2), s.1.div_ceil(2));
        out.push(s);
    }
    out
}

/// The image holding all levels: level 0's width plus level 1's, and the taller of level 0
/// and the column of levels 1 to [`TOP`].
pub fn image_size(width: u32, height: u32) -> (u32, u32) {
    let l = levels(width, height);
    let column: u32 = l[1..].iter().map(|s| s.1).sum();
    (l[0].0 + l[1].0, l[0].1.max(column))
}

/// The pass.
#[derive(Debug)]
pub struct DepthPyramidPass {
    linear: Kernel,
    reduce: Kernel,
}

impl DepthPyramidPass {
    /// Builds the pipelines.
    pub fn new(gpu: &Gpu) -> PlayResult<DepthPyramidPass> {
        use BindingKind::*;
        let push = std::mem::size_of::<ScreenAoConstants>() as u32;
        let [linear, reduce] = Kernel::several(
            gpu,
            [
                (
                    &[Binding::one(Uniform), Binding::one(Sampled), Binding::one(StorageImage)],
                    spirv::PYRAMID_LINEAR,
                ),
                (&[Binding::one(Uniform), Binding::one(StorageImage)], spirv::PYRAMID_REDUCE),
            ],
            push,
        )?;
        Ok(DepthPyramidPass { linear, reduce })
    }
}

impl Pass for DepthPyramidPass {
    fn name(&self) -> &'static str {
        "depth pyramid"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let (w, h) = image_size(width, height);
        vec![(PYRAMID, PYRAMID.sized(w, h, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![DEPTH]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        self.linear.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Sampled(1, vec![(img(&DEPTH), shared.scene.nearest_clamp)]),
                Write::StorageImage(2, img(&PYRAMID)),
            ],
        )?;
        self.reduce.write(gpu, &[Write::Buffer(0, shared.frame_ubo), Write::StorageImage(1, img(&PYRAMID))])
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let (width, height) = (ctx.images.width, ctx.images.height);
        ctx.images
            .access(ctx.rec, &[(DEPTH, Access::Read(Use::SAMPLED)), (PYRAMID, Access::Write(Use::STORAGE))]);
        let push = ScreenAoConstants::default();
        self.linear.dispatch(ctx.rec, bytemuck::bytes_of(&push), width, height);
        for (level, &(w, h)) in levels(width, height).iter().enumerate().skip(1) {
            // Reads the level below, written by the previous dispatch: a barrier between them.
            ctx.images.access(ctx.rec, &[(PYRAMID, Access::ReadWrite(Use::STORAGE))]);
            let push = ScreenAoConstants { level: level as u32, ..Default::default() };
            self.reduce.dispatch(ctx.rec, bytemuck::bytes_of(&push), w, h);
        }
    }

    fn destroy(&mut self, gpu: &Gpu) {
        self.linear.destroy(gpu);
        self.reduce.destroy(gpu);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_halve_rounding_up_and_fit_in_the_image() {
        assert_eq!(levels(96, 72), vec![(96, 72), (48, 36), (24, 18), (12, 9), (6, 5), (3, 3)]);
        assert_eq!(image_size(96, 72), (144, 72));
        // Odd sizes: the column of levels 1.. is taller than level 0 (1 + 1 + 1 + 1 + 1 > 3).
        assert_eq!(levels(3, 3)[1..], [(2, 2), (1, 1), (1, 1), (1, 1), (1, 1)]);
        assert_eq!(image_size(3, 3), (5, 6));
    }
}
