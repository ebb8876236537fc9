//! The camera-space depth pyramid (`shaders/pyramid/`), for the screen-space passes that read
//! depth over large radii (SAO's per-sample MIP level; later SSGI, SSR's Hi-Z).
//!
//! Level 0 is each pixel's distance along the camera's forward axis, from the reversed-Z depth
//! (0 where the sky shows); levels 1 to [`TOP`] halve each side (rounded up). The reduction is
//! **nearest**: a level's pixel copies one of its 2 × 2 children unchanged, picked on McGuire
//! et al.'s rotated grid (2012, §2.2: child (1 − y mod 2, 1 − x mod 2)), so that no level
//! invents a depth between two surfaces (an average would, at every silhouette) and successive
//! levels do not all keep the same corner. Screen-space GI (`--ssgi-mip voting`, its default)
//! picks the child by the seed's **voting** filter instead (seed 000 §3.8: the child whose depth
//! and normal agree best with the 4 × 4 neighbourhood's means), which keeps the large
//! consistent regions and flickers less; it reads the **normals pyramid** that GI builds beside
//! the depths (octahedral normals, the same child copied).
//!
//! All levels live in one `r32f` image (level 0 at the origin, levels 1.. in a column to its
//! right; `shaders/common/screen_ao.glsl` spells the layout), so the graph tracks one image.
//! Each level's dispatch declares the image read-written: the graph then puts a barrier
//! (storage write → storage read/write, whole image) between consecutive levels, which orders
//! every level after the one it reads. Coarser than per-level barriers, but sound and cheap at
//! six dispatches.

use kiln_format::gpu::ScreenAoConstants;

use super::gbuffer::{DEPTH, NORMAL};
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The coarsest level (`PYRAMID_TOP` in `shaders/common/screen_ao.glsl`): seven halvings take
/// 1920 × 1080 to 15 × 9.
pub const TOP: u32 = 7;

/// The pyramid's levels in one image.
pub const PYRAMID: TargetDecl = TargetDecl {
    name: "depth pyramid",
    format: vk::Format::R32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The normals pyramid (octahedral world normals), in the same layout.
pub const NORMAL_PYRAMID: TargetDecl = TargetDecl {
    name: "normal pyramid",
    format: vk::Format::R16G16_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// How a level picks each texel among its 2 × 2 children.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reduction {
    /// McGuire et al.'s rotated grid.
    Nearest,
    /// Seed 000's voting filter (needs the normals pyramid, which it then builds).
    Voting,
}

/// The size of every level, 0 to [`TOP`], for a `width` × `height` screen.
pub fn levels(width: u32, height: u32) -> Vec<(u32, u32)> {
    levels_up_to(width, height, TOP)
}

/// The size of every level, 0 to `top`, each side halved from the one below (rounded up, so
/// that every child's parent is child / 2): the layout every atlas pyramid shares (this one,
/// the lit and GI pyramids, SSR's Hi-Z).
pub fn levels_up_to(width: u32, height: u32, top: u32) -> Vec<(u32, u32)> {
    let mut s = (width.max(1), height.max(1));
    let mut out = vec![s];
    for _ in 0..top {
        s = (s.0.div_ceil(2), s.1.div_ceil(2));
        out.push(s);
    }
    out
}

/// The image holding levels 0 to [`TOP`].
pub fn image_size(width: u32, height: u32) -> (u32, u32) {
    atlas_size(width, height, TOP)
}

/// The image holding levels 0 to `top` (at least 1): level 0's width plus level 1's, and the
/// taller of level 0 and the column of levels 1 to `top`.
pub fn atlas_size(width: u32, height: u32, top: u32) -> (u32, u32) {
    let l = levels_up_to(width, height, top.max(1));
    let column: u32 = l[1..].iter().map(|s| s.1).sum();
    (l[0].0 + l[1].0, l[0].1.max(column))
}

/// The pass.
#[derive(Debug)]
pub struct DepthPyramidPass {
    linear: Kernel,
    reduce: Kernel,
    /// Levels 0 to 5 in one dispatch (nearest, no normals: SAO's pyramid).
    single: Kernel,
    reduction: Reduction,
    normals: bool,
    /// The coarsest level built (the readers need no coarser one).
    top: u32,
}

impl DepthPyramidPass {
    /// Builds the pipelines of a pyramid of levels 0 to `top` (at most [`TOP`]; the image always
    /// has room for all), reduced as `reduction` says, with the normals pyramid when `normals`
    /// (always with [`Reduction::Voting`]).
    pub fn new(gpu: &Gpu, reduction: Reduction, normals: bool, top: u32) -> PlayResult<DepthPyramidPass> {
        use BindingKind::*;
        let push = std::mem::size_of::<ScreenAoConstants>() as u32;
        let [linear, reduce, single] = Kernel::several(
            gpu,
            [
                (
                    &[
                        Binding::one(Uniform),
                        Binding::one(Sampled),
                        Binding::one(StorageImage),
                        Binding::one(Sampled),
                        Binding::one(StorageImage),
                    ],
                    spirv::shader!("pyramid/linear.comp"),
                ),
                (
                    &[Binding::one(Uniform), Binding::one(StorageImage), Binding::one(StorageImage)],
                    spirv::shader!("pyramid/reduce.comp"),
                ),
                (
                    &[Binding::one(Uniform), Binding::one(Sampled), Binding::one(StorageImage)],
                    spirv::shader!("pyramid/single.comp"),
                ),
            ],
            push,
        )?;
        let normals = normals || reduction == Reduction::Voting;
        Ok(DepthPyramidPass { linear, reduce, single, reduction, normals, top: top.min(TOP) })
    }

    /// Whether one dispatch makes the whole pyramid (`shaders/pyramid/single.comp`): a nearest
    /// reduction without normals to at most level 5, whose 32 × 32-pixel blocks reduce alone.
    fn single_pass(&self) -> bool {
        self.reduction == Reduction::Nearest && !self.normals && (1..=5).contains(&self.top)
    }

    fn push(&self, level: u32) -> ScreenAoConstants {
        ScreenAoConstants {
            level,
            voting: (self.reduction == Reduction::Voting) as u32,
            normals: self.normals as u32,
            ..Default::default()
        }
    }
}

impl Pass for DepthPyramidPass {
    fn name(&self) -> &'static str {
        "depth pyramid"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let (w, h) = image_size(width, height);
        let mut made = vec![(PYRAMID, PYRAMID.sized(w, h, 1))];
        if self.normals {
            made.push((NORMAL_PYRAMID, NORMAL_PYRAMID.sized(w, h, 1)));
        }
        made
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![DEPTH, NORMAL, NORMAL_PYRAMID]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        self.linear.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Sampled(1, vec![(img(&DEPTH), shared.scene.nearest_clamp)]),
                Write::StorageImage(2, img(&PYRAMID)),
                Write::Sampled(3, vec![(img(&NORMAL), shared.scene.nearest_clamp)]),
                Write::StorageImage(4, img(&NORMAL_PYRAMID)),
            ],
        )?;
        self.single.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Sampled(1, vec![(img(&DEPTH), shared.scene.nearest_clamp)]),
                Write::StorageImage(2, img(&PYRAMID)),
            ],
        )?;
        self.reduce.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::StorageImage(1, img(&PYRAMID)),
                Write::StorageImage(2, img(&NORMAL_PYRAMID)),
            ],
        )
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let (width, height) = (ctx.images.width, ctx.images.height);
        if self.single_pass() {
            ctx.images.access(
                ctx.rec,
                &[(DEPTH, Access::Read(Use::SAMPLED)), (PYRAMID, Access::Write(Use::STORAGE))],
            );
            let push = ScreenAoConstants { level: self.top, ..Default::default() };
            // 16 × 16 threads per 32 × 32 pixels: the dispatch helper counts 8 × 8 groups.
            self.single.dispatch(ctx.rec, bytemuck::bytes_of(&push), width.div_ceil(4), height.div_ceil(4));
            return;
        }
        // The normals pyramid too when it is a placeholder: its descriptor needs the layout.
        let written = [(PYRAMID, Access::Write(Use::STORAGE)), (NORMAL_PYRAMID, Access::Write(Use::STORAGE))];
        let mut first = vec![(DEPTH, Access::Read(Use::SAMPLED)), (NORMAL, Access::Read(Use::SAMPLED))];
        first.extend(&written);
        ctx.images.access(ctx.rec, &first);
        self.linear.dispatch(ctx.rec, bytemuck::bytes_of(&self.push(0)), width, height);
        for (level, &(w, h)) in levels(width, height).iter().enumerate().skip(1).take(self.top as usize) {
            // Reads the level below, written by the previous dispatch: a barrier between them.
            let again: Vec<_> = written.iter().map(|&(t, _)| (t, Access::ReadWrite(Use::STORAGE))).collect();
            ctx.images.access(ctx.rec, &again);
            self.reduce.dispatch(ctx.rec, bytemuck::bytes_of(&self.push(level as u32)), w, h);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_halve_rounding_up_and_fit_in_the_image() {
        assert_eq!(
            levels(96, 72),
            vec![(96, 72), (48, 36), (24, 18), (12, 9), (6, 5), (3, 3), (2, 2), (1, 1)]
        );
        assert_eq!(image_size(96, 72), (144, 74));
        // Odd sizes: the column of levels 1.. is taller than level 0 (2 + 1 + … + 1 > 3).
        assert_eq!(levels(3, 3)[1..], [(2, 2), (1, 1), (1, 1), (1, 1), (1, 1), (1, 1), (1, 1)]);
        assert_eq!(image_size(3, 3), (5, 8));
    }
}
