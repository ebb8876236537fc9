//! Temporal anti-aliasing (`--aa taa`, `shaders/taa/resolve.comp`): this frame's radiance,
//! rendered through a jittered projection ([`crate::render::taa_jitter`]), blended into the
//! history reprojected from the previous camera and clamped to the frame's neighbourhood.
//!
//! Two history images (half floats) take turns: frame n reads the one frame n − 1 wrote and
//! writes the other. The result is then written over the radiance (`output.comp`), so that tone
//! mapping and read-back see the anti-aliased image without knowing which history holds it (its
//! alpha carries the history length).

use super::direct::RADIANCE;
use super::gbuffer::DEPTH;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

const fn history(name: &'static str) -> TargetDecl {
    TargetDecl {
        name,
        format: vk::Format::R16G16B16A16_SFLOAT,
        usage: vk::ImageUsageFlags::from_raw(
            vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
        ),
        array: false,
    }
}

/// The histories (anti-aliased radiance, alpha the frames of history behind it), in turn.
pub const HISTORIES: [TargetDecl; 2] = [history("taa history a"), history("taa history b")];

/// The push constants of `resolve.comp`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Push {
    frames: f32,
    luma_weights: u32,
}

/// The TAA pass.
#[derive(Debug)]
pub struct TaaPass {
    kernel: Kernel,
    /// History → radiance (`output.comp`); set i reads history i.
    output: Kernel,
    push: Push,
    /// Which history the next frame writes.
    turn: usize,
}

impl TaaPass {
    /// Builds the pipeline: histories of at most `frames` frames, blended with Karis's luma
    /// weights or linearly.
    pub fn new(gpu: &Gpu, frames: u32, luma_weights: bool) -> PlayResult<TaaPass> {
        use BindingKind::*;
        let bindings = [
            Binding::one(Uniform),
            Binding::one(StorageImage),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(StorageImage),
        ];
        let push = Push { frames: frames.max(1) as f32, luma_weights: luma_weights as u32 };
        let output_bindings = [Binding::one(Uniform), Binding::one(StorageImage), Binding::one(StorageImage)];
        let [kernel, output] = Kernel::several(
            gpu,
            [
                (&bindings, spirv::shader!("taa/resolve.comp")),
                (&output_bindings, spirv::shader!("taa/output.comp")),
            ],
            std::mem::size_of::<Push>() as u32,
        )?;
        Ok(TaaPass { kernel, output, push, turn: 0 })
    }
}

impl Pass for TaaPass {
    fn name(&self) -> &'static str {
        "taa"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        HISTORIES.iter().map(|t| (*t, t.sized(width, height, 1))).collect()
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![RADIANCE, DEPTH]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        // Set i writes history i and reads the other.
        for (i, written) in HISTORIES.iter().enumerate() {
            let read = &HISTORIES[1 - i];
            self.kernel.write_set(
                gpu,
                i,
                &[
                    Write::Buffer(0, shared.frame_ubo),
                    Write::StorageImage(1, img(&RADIANCE)),
                    Write::Sampled(2, vec![(img(read), shared.scene.linear_clamp)]),
                    Write::Sampled(3, vec![(img(&DEPTH), shared.scene.nearest_clamp)]),
                    Write::StorageImage(4, img(written)),
                ],
            )?;
            self.output.write_set(
                gpu,
                i,
                &[
                    Write::Buffer(0, shared.frame_ubo),
                    Write::StorageImage(1, img(written)),
                    Write::StorageImage(2, img(&RADIANCE)),
                ],
            )?;
        }
        // New images: the renderer marks the history invalid for the next frame.
        self.turn = 0;
        Ok(())
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let (written, read) = (HISTORIES[self.turn], HISTORIES[1 - self.turn]);
        ctx.images.access(
            ctx.rec,
            &[
                (RADIANCE, Access::Read(Use::STORAGE)),
                (read, Access::Read(Use::SAMPLED)),
                (DEPTH, Access::Read(Use::SAMPLED)),
                (written, Access::Write(Use::STORAGE)),
            ],
        );
        self.kernel.dispatch_set(
            ctx.rec,
            self.turn,
            bytemuck::bytes_of(&self.push),
            ctx.images.width,
            ctx.images.height,
        );
        ctx.images.access(
            ctx.rec,
            &[(written, Access::Read(Use::STORAGE)), (RADIANCE, Access::Write(Use::STORAGE))],
        );
        self.output.dispatch_set(
            ctx.rec,
            self.turn,
            bytemuck::bytes_of(&self.push),
            ctx.images.width,
            ctx.images.height,
        );
        self.turn = 1 - self.turn;
    }
}
