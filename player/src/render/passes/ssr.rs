//! Screen-space reflections (`--reflections ssr`; `shaders/ssr/trace.comp`): per pixel, the
//! mirror direction marched through the Hi-Z pyramid ([`super::hiz`]), skipping empty space a
//! level up at a time and stepping down where the ray may meet a surface, accepting a hit at the
//! coarsest level that fits in the reflection cone's footprint (rougher: coarser, fewer steps).
//! The hit shows the previous frame's lit radiance ([`super::lit_pyramid`], reprojected into this
//! frame's pixels) at the pyramid level that the cone's footprint there covers (seed 000 §3.9);
//! the result is the incoming radiance with a
//! confidence, 0 where the ray misses or leaves the image, faded near its edges, which the direct
//! pass blends with the split-sum ambient (`FrameFlags::SCREEN_REFLECTIONS`). Deterministic: the
//! image is overwritten every frame.
//!
//! It writes the reflection image the ray-traced reflections make ([`REFLECTIONS`]): the direct
//! pass reads one image whichever technique makes it, as with the AO image.

use kiln_format::gpu::SsrConstants;

use super::gbuffer::{DEPTH, MATERIAL, NORMAL};
use super::hiz::{HIZ, TOP};
use super::kernel::Kernel;
use super::lit_pyramid::LIT_PYRAMID;
use super::rt_reflections::REFLECTIONS;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// How far a ray may pass behind the surface the depth buffer holds and still count as meeting
/// it, as a fraction of that surface's camera depth. The march finds a hit where the ray reaches a
/// cell's depth inside the cell; a ray that enters a cell already behind its surface has met it
/// edge-on only if it is within about the depth a tilted surface spans across a pixel (its depth
/// is taken at the pixel's centre), and otherwise passes behind it: the depth buffer holds only
/// the front of things. 1 % keeps a ray that passes a tenth of a unit under an object 5 units
/// away from counting as a hit (`tests/render/ssr.rs`).
pub const THICKNESS: f32 = 0.01;

/// The G-buffer targets it samples, in binding order (1–3).
const GBUFFER: [TargetDecl; 3] = [DEPTH, NORMAL, MATERIAL];

/// The SSR pass.
#[derive(Debug)]
pub struct SsrPass {
    kernel: Kernel,
    constants: SsrConstants,
}

impl SsrPass {
    /// Builds the pipeline: at most `steps` iterations of the march per pixel, surfaces rougher
    /// than `max_roughness` left to the split-sum ambient.
    pub fn new(gpu: &Gpu, steps: u32, max_roughness: f32) -> PlayResult<SsrPass> {
        use BindingKind::*;
        let bindings = [
            Binding::one(Uniform),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
        ];
        let push = std::mem::size_of::<SsrConstants>() as u32;
        let kernel = Kernel::new(gpu, &bindings, spirv::shader!("ssr/trace.comp"), push)?;
        let constants =
            SsrConstants { steps: steps.max(1), max_roughness, thickness: THICKNESS, top: TOP, level: 0 };
        Ok(SsrPass { kernel, constants })
    }
}

impl Pass for SsrPass {
    fn name(&self) -> &'static str {
        "ssr"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(REFLECTIONS, REFLECTIONS.sized(width, height, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        let mut b = GBUFFER.to_vec();
        b.extend([HIZ, LIT_PYRAMID]);
        b
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        let mut writes = vec![Write::Buffer(0, shared.frame_ubo)];
        for (i, t) in GBUFFER.iter().enumerate() {
            writes.push(Write::Sampled(1 + i as u32, vec![(img(t), shared.scene.nearest_clamp)]));
        }
        writes.extend([
            Write::StorageImage(4, img(&HIZ)),
            Write::StorageImage(5, img(&LIT_PYRAMID)),
            Write::StorageImage(6, img(&REFLECTIONS)),
        ]);
        self.kernel.write(gpu, &writes)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let mut io = super::gbuffer::sampled(&GBUFFER);
        io.extend([
            (HIZ, Access::Read(Use::STORAGE)),
            (LIT_PYRAMID, Access::Read(Use::STORAGE)),
            (REFLECTIONS, Access::Write(Use::STORAGE)),
        ]);
        ctx.images.access(ctx.rec, &io);
        let push = bytemuck::bytes_of(&self.constants);
        self.kernel.dispatch(ctx.rec, push, ctx.images.width, ctx.images.height);
    }
}
