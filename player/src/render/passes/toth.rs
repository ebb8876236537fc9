//! Tóth & Umenhoffer's shadow-map ray march (`--media toth`, seed 002 §7, its errata fixed):
//! each view ray marched through the media in world space with a fixed sample count, the
//! lights' visibility from the compiler's shadow maps, the samples interleaved over a block of
//! pixels (`shaders/toth/march.comp`), then a depth-aware blur over the block that joins them,
//! dims the surface behind by the media's transmittance and adds the light scattered
//! (`shaders/toth/blur.comp`). World space: it holds with the light off screen or behind the
//! camera.

use kiln_format::gpu::TothConstants;

use super::direct::RADIANCE;
use super::gbuffer::DEPTH;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::{MAX_SHADOW_MAPS, spirv};

/// The light scattered towards the camera per pixel, before the blur.
pub const SCATTER: TargetDecl = TargetDecl {
    name: "toth scatter",
    format: vk::Format::R16G16B16A16_SFLOAT,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
    ),
    array: false,
};

/// The pass.
#[derive(Debug)]
pub struct TothPass {
    march: Kernel,
    blur: Kernel,
    constants: TothConstants,
    /// Whether the scene has media (without, the pass records nothing).
    active: bool,
}

impl TothPass {
    /// Builds the pipelines: `samples` along each view ray, interleaved over `block` × `block`
    /// pixels, with the phase function `phase` (`Phases`).
    pub fn new(gpu: &Gpu, samples: u32, block: u32, phase: u32) -> PlayResult<TothPass> {
        use BindingKind::*;
        let push = std::mem::size_of::<TothConstants>() as u32;
        let maps = Binding { kind: Sampled, count: MAX_SHADOW_MAPS as u32 };
        let [march, blur] = Kernel::several(
            gpu,
            [
                (
                    &[
                        Binding::one(Uniform),
                        Binding::one(Storage),
                        Binding::one(Storage),
                        maps,
                        maps,
                        Binding::one(Storage),
                        Binding::one(Sampled),
                        Binding::one(StorageImage),
                    ],
                    spirv::shader!("toth/march.comp"),
                ),
                (
                    &[
                        Binding::one(Uniform),
                        Binding::one(Storage),
                        Binding::one(Sampled),
                        Binding::one(Sampled),
                        Binding::one(StorageImage),
                    ],
                    spirv::shader!("toth/blur.comp"),
                ),
            ],
            push,
        )?;
        let constants = TothConstants { samples: samples.max(1), block: block.max(1), phase, media: 0 };
        Ok(TothPass { march, blur, constants, active: false })
    }
}

impl Pass for TothPass {
    fn name(&self) -> &'static str {
        "media"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(SCATTER, SCATTER.sized(width, height, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![DEPTH, RADIANCE]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let Some(m) = shared.scene.media.as_ref().filter(|m| m.count > 0) else {
            self.active = false;
            return Ok(());
        };
        self.active = true;
        self.constants.media = m.count;
        let near = shared.scene.nearest_clamp;
        let (maps_2d, maps_cube) = super::shadow_map_arrays(shared);
        let img = |t: &TargetDecl| shared.images.get(t).view;
        self.march.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Buffer(1, shared.lights),
                Write::Buffer(2, shared.shadows),
                Write::Sampled(3, maps_2d),
                Write::Sampled(4, maps_cube),
                Write::Buffer(5, &m.table),
                Write::Sampled(6, vec![(img(&DEPTH), near)]),
                Write::StorageImage(7, img(&SCATTER)),
            ],
        )?;
        self.blur.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Buffer(1, &m.table),
                Write::Sampled(2, vec![(img(&DEPTH), near)]),
                Write::Sampled(3, vec![(img(&SCATTER), near)]),
                Write::StorageImage(4, img(&RADIANCE)),
            ],
        )
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        if !self.active {
            return;
        }
        let push = bytemuck::bytes_of(&self.constants);
        let (width, height) = (ctx.images.width, ctx.images.height);
        ctx.images
            .access(ctx.rec, &[(DEPTH, Access::Read(Use::SAMPLED)), (SCATTER, Access::Write(Use::STORAGE))]);
        self.march.dispatch(ctx.rec, push, width, height);
        ctx.images.access(
            ctx.rec,
            &[
                (DEPTH, Access::Read(Use::SAMPLED)),
                (SCATTER, Access::Read(Use::SAMPLED)),
                (RADIANCE, Access::ReadWrite(Use::STORAGE)),
            ],
        );
        self.blur.dispatch(ctx.rec, push, width, height);
    }
}
