//! Screen-space diffuse GI (`--gi ssgi`; seed 000 §2.1, §3.5–3.7; `shaders/ssgi/`).
//!
//! Reads the depth and normal pyramids ([`super::depth_pyramid`], voting or nearest) and the
//! lit-radiance pyramid ([`super::lit_pyramid`], the previous frame's light), and:
//! 1. `pack.comp`: depth, normal and light packed into one texel (one fetch per sample);
//! 2. `gather.comp`, once per level from the coarsest needed down to the GI resolution: each
//!    texel gathers spiral samples of that level's light within R texels and adds the coarser
//!    level's result, joint-bilaterally upsampled (`upsample.glsl`);
//! 3. `resolve.comp`: the finest result upsampled to the screen the same way, as mean incoming
//!    radiance, averaged over the frames the camera has been still, into the GI image that the
//!    direct pass adds to the sky's ambient (`FrameFlags::SCREEN_GI`).
//!
//! The coarsest level is the first whose diagonal one radius spans (seed 000 §3.6: the whole
//! screen is then within reach of every pixel), at most [`super::depth_pyramid::TOP`].

use kiln_format::gpu::ScreenGiConstants;

use super::depth_pyramid::{NORMAL_PYRAMID, PYRAMID, TOP, image_size, levels};
use super::kernel::Kernel;
use super::lit_pyramid::LIT_PYRAMID;
use super::rt_gi::GI;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;
use crate::render::techniques::ScreenFraction;

/// Each level's gathered irradiance (plus everything coarser), in the pyramids' layout.
pub const GI_LEVELS: TargetDecl = TargetDecl {
    name: "ssgi levels",
    format: vk::Format::R16G16B16A16_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The depth, normal and light pyramids packed into one texel each (`pack.comp`).
pub const PACKED: TargetDecl = TargetDecl {
    name: "ssgi packed",
    format: vk::Format::R32G32B32A32_UINT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The levels gathered on a `width` × `height` screen: from `base` up to the first level whose
/// diagonal `radius` texels span (at least `base`, at most [`TOP`]).
pub fn gathered_levels(width: u32, height: u32, base: u32, radius: f32) -> (u32, u32) {
    let base = base.min(TOP);
    let sizes = levels(width, height);
    let top = (base..=TOP)
        .find(|&k| {
            let (w, h) = sizes[k as usize];
            ((w as f32).powi(2) + (h as f32).powi(2)).sqrt() <= radius
        })
        .unwrap_or(TOP);
    (base, top)
}

/// The pass.
#[derive(Debug)]
pub struct SsgiPass {
    pack: Kernel,
    gather: Kernel,
    resolve: Kernel,
    constants: ScreenGiConstants,
}

impl SsgiPass {
    /// Builds the pipelines: `samples` spiral samples per pixel on each level of radius
    /// `radius` pixels, the finest level at `resolution`, the seed's fall-off when `falloff`,
    /// a running mean of at most `frames`, one spiral rotation per 8 × 8 texels when `tiled`.
    pub fn new(
        gpu: &Gpu,
        samples: u32,
        resolution: ScreenFraction,
        radius: u32,
        falloff: bool,
        frames: u32,
        tiled: bool,
    ) -> PlayResult<SsgiPass> {
        use BindingKind::*;
        let push = std::mem::size_of::<ScreenGiConstants>() as u32;
        let bindings = [
            Binding::one(Uniform),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
        ];
        // The resolve reads the packed pyramid too (binding 5).
        let mut resolve_bindings = bindings.to_vec();
        resolve_bindings.push(Binding::one(StorageImage));
        let [pack, gather, resolve] = Kernel::several(
            gpu,
            [
                (&bindings, spirv::shader!("ssgi/pack.comp")),
                (&bindings, spirv::shader!("ssgi/gather.comp")),
                (&resolve_bindings, spirv::shader!("ssgi/resolve.comp")),
            ],
            push,
        )?;
        let constants = ScreenGiConstants {
            base: resolution.divisor().trailing_zeros(),
            samples: samples.max(1),
            radius: radius.max(1) as f32,
            cap: frames.max(1),
            falloff: falloff as u32,
            tiled: tiled as u32,
            ..Default::default()
        };
        Ok(SsgiPass { pack, gather, resolve, constants })
    }
}

impl Pass for SsgiPass {
    fn name(&self) -> &'static str {
        "ssgi"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let (w, h) = image_size(width, height);
        vec![
            (PACKED, PACKED.sized(w, h, 1)),
            (GI_LEVELS, GI_LEVELS.sized(w, h, 1)),
            (GI, GI.sized(width, height, 1)),
        ]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![PYRAMID, NORMAL_PYRAMID, LIT_PYRAMID]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        // Every kernel: frame constants, depth and normal pyramids, what it reads, what it writes.
        let writes = |read: &TargetDecl, written: &TargetDecl| {
            [
                Write::Buffer(0, shared.frame_ubo),
                Write::StorageImage(1, img(&PYRAMID)),
                Write::StorageImage(2, img(&NORMAL_PYRAMID)),
                Write::StorageImage(3, img(read)),
                Write::StorageImage(4, img(written)),
            ]
        };
        self.pack.write(gpu, &writes(&LIT_PYRAMID, &PACKED))?;
        self.gather.write(gpu, &writes(&PACKED, &GI_LEVELS))?;
        let mut resolve = Vec::from(writes(&GI_LEVELS, &GI));
        resolve.push(Write::StorageImage(5, img(&PACKED)));
        self.resolve.write(gpu, &resolve)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let (width, height) = (ctx.images.width, ctx.images.height);
        let (base, top) = gathered_levels(width, height, self.constants.base, self.constants.radius);
        let sizes = levels(width, height);
        let mut push = ScreenGiConstants {
            base,
            top,
            accumulated: ctx.rt.accumulated,
            seed: ctx.rt.seed,
            ..self.constants
        };
        ctx.images.access(
            ctx.rec,
            &[
                (PYRAMID, Access::Read(Use::STORAGE)),
                (NORMAL_PYRAMID, Access::Read(Use::STORAGE)),
                (LIT_PYRAMID, Access::Read(Use::STORAGE)),
                (PACKED, Access::Write(Use::STORAGE)),
            ],
        );
        // The whole pyramid image, or (gathering from level 1 up) the column of levels 1...
        let (w, h) = image_size(width, height);
        let packed_width = if base == 0 { w } else { w - width };
        self.pack.dispatch(ctx.rec, bytemuck::bytes_of(&push), packed_width, h);
        for level in (base..=top).rev() {
            // Each level reads the coarser one the previous dispatch wrote.
            ctx.images.access(
                ctx.rec,
                &[
                    (PYRAMID, Access::Read(Use::STORAGE)),
                    (NORMAL_PYRAMID, Access::Read(Use::STORAGE)),
                    (PACKED, Access::Read(Use::STORAGE)),
                    (GI_LEVELS, Access::ReadWrite(Use::STORAGE)),
                ],
            );
            push.level = level;
            let (w, h) = sizes[level as usize];
            self.gather.dispatch(ctx.rec, bytemuck::bytes_of(&push), w, h);
        }
        ctx.images.access(
            ctx.rec,
            &[
                (PYRAMID, Access::Read(Use::STORAGE)),
                (NORMAL_PYRAMID, Access::Read(Use::STORAGE)),
                (PACKED, Access::Read(Use::STORAGE)),
                (GI_LEVELS, Access::Read(Use::STORAGE)),
                (GI, Access::ReadWrite(Use::STORAGE)),
            ],
        );
        self.resolve.dispatch(ctx.rec, bytemuck::bytes_of(&push), width, height);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_coarsest_level_is_the_first_one_radius_spans() {
        // 1920 × 1080: level 6 is 30 × 17 (diagonal 34.5), level 5 60 × 34 (69).
        assert_eq!(gathered_levels(1920, 1080, 1, 40.0), (1, 6));
        // A small screen stops early: 96 × 72 has level 2 at 24 × 18 (diagonal 30).
        assert_eq!(gathered_levels(96, 72, 1, 40.0), (1, 2));
        assert_eq!(gathered_levels(96, 72, 0, 40.0), (0, 2));
        // The base level is always gathered.
        assert_eq!(gathered_levels(16, 16, 2, 40.0), (2, 2));
        // A tiny radius never spans the screen: the top of the pyramid.
        assert_eq!(gathered_levels(1920, 1080, 0, 4.0), (0, TOP));
    }
}
