//! Sousa's sun shafts (`--media sousa`, seed 002 §6): the camera's depth map at a fraction of
//! the screen's resolution (`shaders/sousa/depth.comp`: far is bright), then per light three
//! chained radial blurs towards its screen position with steps TAPS⁻¹, TAPS⁻², TAPS⁻³ of the
//! screen (interleaved sampling): the first two at the depth map's resolution in 16-bit floats
//! (`shaders/sousa/blur.comp`), the last at the screen's, added to the radiance
//! (`shaders/sousa/composite.comp`). A light behind the camera gives no shafts (the method's
//! known failure).

use kiln_format::gpu::GodRayConstants;

use super::direct::RADIANCE;
use super::gbuffer::DEPTH;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;
use crate::render::techniques::ScreenFraction;

const fn small_target(name: &'static str) -> TargetDecl {
    TargetDecl {
        name,
        format: vk::Format::R16_SFLOAT,
        usage: vk::ImageUsageFlags::from_raw(
            vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
        ),
        array: false,
    }
}

/// The tap count the seed tuned its brightness of 0.19 for (Fig. 3.8).
pub const SEED_TAPS: u32 = 6;

/// The depth map (view distance over the scene's diagonal, the sky 1).
pub const DEPTH_MAP: TargetDecl = small_target("sousa depth");
/// The first blur's output.
pub const FIRST: TargetDecl = small_target("sousa first blur");
/// The second blur's output.
pub const SECOND: TargetDecl = small_target("sousa second blur");

/// The pass.
#[derive(Debug)]
pub struct SousaPass {
    depth: Kernel,
    /// Set 0: depth map → first; set 1: first → second.
    blur: Kernel,
    composite: Kernel,
    constants: GodRayConstants,
    divisor: u32,
    /// Lights to blur towards (0 without a medium: the pass records nothing).
    lights: u32,
}

fn kernels(gpu: &Gpu, push: u32) -> PlayResult<[Kernel; 3]> {
    use BindingKind::*;
    let blur_bindings = [
        Binding::one(Uniform),
        Binding::one(Storage),
        Binding::one(Storage),
        Binding::one(Sampled),
        Binding::one(StorageImage),
    ];
    Kernel::several(
        gpu,
        [
            (
                &[Binding::one(Uniform), Binding::one(Sampled), Binding::one(StorageImage)],
                spirv::shader!("sousa/depth.comp"),
            ),
            (&blur_bindings, spirv::shader!("sousa/blur.comp")),
            (&blur_bindings, spirv::shader!("sousa/composite.comp")),
        ],
        push,
    )
}

impl SousaPass {
    /// Builds the pipelines: `taps` samples per pass, the depth map and first two passes at
    /// `resolution`, each pass's sum times `brightness`.
    pub fn new(gpu: &Gpu, taps: u32, resolution: ScreenFraction, brightness: f32) -> PlayResult<SousaPass> {
        let [depth, blur, composite] = kernels(gpu, std::mem::size_of::<GodRayConstants>() as u32)?;
        // The brightness is the seed's, tuned for its 6 taps: per sample it is scaled by 6/TAPS so
        // that more taps refine the shafts instead of brightening them.
        let taps = taps.max(1);
        let gain = brightness * SEED_TAPS as f32 / taps as f32;
        let constants = GodRayConstants { samples: taps, gain, ..Default::default() };
        Ok(SousaPass { depth, blur, composite, constants, divisor: resolution.divisor(), lights: 0 })
    }

    /// Pass `k`'s (0, 1, 2) constants for `light`: step TAPS^−(k+1).
    fn constants(&self, light: u32, k: i32) -> GodRayConstants {
        GodRayConstants { light, step: (self.constants.samples as f32).powi(-(k + 1)), ..self.constants }
    }
}

impl Pass for SousaPass {
    fn name(&self) -> &'static str {
        "media"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let (w, h) = (width.div_ceil(self.divisor), height.div_ceil(self.divisor));
        [DEPTH_MAP, FIRST, SECOND].iter().map(|t| (*t, t.sized(w, h, 1))).collect()
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![DEPTH, RADIANCE]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let Some(m) = shared.scene.media.as_ref().filter(|m| m.count > 0) else {
            self.lights = 0;
            return Ok(());
        };
        self.lights = shared.plan.lights_used;
        self.constants.extent = shared.scene.diagonal().max(f32::MIN_POSITIVE);
        self.constants.media = m.count;
        let img = |t: &TargetDecl| shared.images.get(t).view;
        let (near, linear) = (shared.scene.nearest_clamp, shared.scene.linear_clamp);
        self.depth.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Sampled(1, vec![(img(&DEPTH), near)]),
                Write::StorageImage(2, img(&DEPTH_MAP)),
            ],
        )?;
        let chain = |from: &TargetDecl, to| {
            vec![
                Write::Buffer(0, shared.frame_ubo),
                Write::Buffer(1, shared.lights),
                Write::Buffer(2, &m.table),
                Write::Sampled(3, vec![(img(from), linear)]),
                Write::StorageImage(4, to),
            ]
        };
        self.blur.write_set(gpu, 0, &chain(&DEPTH_MAP, img(&FIRST)))?;
        self.blur.write_set(gpu, 1, &chain(&FIRST, img(&SECOND)))?;
        self.composite.write(gpu, &chain(&SECOND, img(&RADIANCE)))
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        if self.lights == 0 {
            return;
        }
        let small = ctx.images.get(&DEPTH_MAP).desc;
        let (width, height) = (ctx.images.width, ctx.images.height);
        ctx.images.access(
            ctx.rec,
            &[(DEPTH, Access::Read(Use::SAMPLED)), (DEPTH_MAP, Access::Write(Use::STORAGE))],
        );
        self.depth.dispatch(ctx.rec, bytemuck::bytes_of(&self.constants), small.width, small.height);
        for light in 0..self.lights {
            for (k, (from, to)) in [(DEPTH_MAP, FIRST), (FIRST, SECOND)].into_iter().enumerate() {
                ctx.images.access(
                    ctx.rec,
                    &[(from, Access::Read(Use::SAMPLED)), (to, Access::Write(Use::STORAGE))],
                );
                let push = self.constants(light, k as i32);
                self.blur.dispatch_set(ctx.rec, k, bytemuck::bytes_of(&push), small.width, small.height);
            }
            ctx.images.access(
                ctx.rec,
                &[(SECOND, Access::Read(Use::SAMPLED)), (RADIANCE, Access::ReadWrite(Use::STORAGE))],
            );
            let push = self.constants(light, 2);
            self.composite.dispatch(ctx.rec, bytemuck::bytes_of(&push), width, height);
        }
    }
}
