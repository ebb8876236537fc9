//! The spatiotemporal denoiser of the ray-traced signals (`--denoise svgf`;
//! `shaders/denoise/svgf.glsl` says what each step computes): SVGF's variance-guided à-trous
//! filter over the running means the ray-traced passes keep, which stay unfiltered (a still
//! image converges to the same mean as without it). Each noisy signal ([`Noisy`]) is filtered
//! into an image of its own that the composition reads instead of the signal.

use super::gbuffer::{ALBEDO, DEPTH, NORMAL};
use super::kernel::Kernel;
use super::rt_history::SAMPLES;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;
use kiln_format::gpu::DenoiseConstants;

const fn storage(name: &'static str, format: vk::Format) -> TargetDecl {
    TargetDecl { name, format, usage: vk::ImageUsageFlags::STORAGE, array: false }
}

/// The denoised direct light of the emissive surfaces (what the composition reads in place of
/// `rt_direct::DIRECT` when the denoiser runs).
pub const DIRECT_DENOISED: TargetDecl = storage("rt direct denoised", vk::Format::R32G32B32A32_SFLOAT);
/// The denoised GI (in place of `rt_gi::GI`).
pub const GI_DENOISED: TargetDecl = storage("rt gi denoised", vk::Format::R32G32B32A32_SFLOAT);
/// Per pixel: camera-relative position and packed normal.
const GUIDE: TargetDecl = storage("denoise guide", vk::Format::R32G32B32A32_UINT);
/// The filter's two images (demodulated rgb, variance), taking turns.
const PING_PONG: [TargetDecl; 2] = [
    storage("denoise a", vk::Format::R32G32B32A32_SFLOAT),
    storage("denoise b", vk::Format::R32G32B32A32_SFLOAT),
];

/// A noisy signal a ray-traced technique makes (`Technique::noisy`): its running mean (rgb, and
/// the mean of its demodulated luminance squared in alpha) and where the denoised image goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noisy {
    /// The running mean the technique writes.
    pub target: TargetDecl,
    /// The denoised image the composition reads instead.
    pub output: TargetDecl,
    /// Whether the signal carries the surface's albedo (divided out while filtering).
    pub demodulate: bool,
}

/// The filter's settings (the technique's knobs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Filter {
    /// À-trous iterations (iteration i's taps 2^i pixels apart: k iterations reach
    /// 2 (2^k − 1) pixels).
    pub iterations: u32,
    /// Luminance edge-stopping in standard deviations of the noise.
    pub sigma_luminance: f32,
    /// Normal edge-stopping exponent.
    pub sigma_normal: f32,
    /// Depth edge-stopping in pixel footprints per pixel of separation.
    pub sigma_plane: f32,
}

/// The pass.
#[derive(Debug)]
pub struct DenoisePass {
    guide: Kernel,
    variance: Kernel,
    atrous: Kernel,
    signals: Vec<Noisy>,
    filter: Filter,
    /// Whether the running means are reprojected (samples per pixel from the history pass).
    reprojected: bool,
}

impl DenoisePass {
    /// The pass over `signals`; `reprojected`: whether the ray-traced passes' history is
    /// reprojected (each pixel's sample count then comes from `rt_history::SAMPLES`).
    pub fn new(gpu: &Gpu, signals: Vec<Noisy>, filter: Filter, reprojected: bool) -> PlayResult<DenoisePass> {
        use BindingKind::*;
        let guide: &[Binding] = &[
            Binding::one(Uniform),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(StorageImage),
        ];
        let filtering: &[Binding] = &[
            Binding::one(Uniform),
            Binding::one(Sampled),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
        ];
        let push = std::mem::size_of::<DenoiseConstants>() as u32;
        let [guide, variance, atrous] = Kernel::several(
            gpu,
            [
                (guide, spirv::shader!("denoise/guide.comp")),
                (filtering, spirv::shader!("denoise/variance.comp")),
                (filtering, spirv::shader!("denoise/atrous.comp")),
            ],
            push,
        )?;
        let filter = Filter { iterations: filter.iterations.max(1), ..filter };
        Ok(DenoisePass { guide, variance, atrous, signals, filter, reprojected })
    }

    fn constants(&self, signal: &Noisy, samples: u32, iteration: u32) -> DenoiseConstants {
        DenoiseConstants {
            samples,
            step: 1 << iteration,
            demodulate: signal.demodulate as u32,
            last: (iteration + 1 == self.filter.iterations) as u32,
            sigma_luminance: self.filter.sigma_luminance,
            sigma_normal: self.filter.sigma_normal,
            sigma_plane: self.filter.sigma_plane,
        }
    }
}

impl Pass for DenoisePass {
    fn name(&self) -> &'static str {
        "denoise"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let mut made: Vec<TargetDecl> = vec![GUIDE, PING_PONG[0], PING_PONG[1]];
        made.extend(self.signals.iter().map(|s| s.output));
        made.into_iter().map(|t| (t, t.sized(width, height, 1))).collect()
    }

    fn binds(&self) -> Vec<TargetDecl> {
        let mut b = vec![DEPTH, NORMAL, ALBEDO, SAMPLES];
        b.extend(self.signals.iter().map(|s| s.target));
        b
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        let near = shared.scene.nearest_clamp;
        self.guide.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Sampled(1, vec![(img(&DEPTH), near)]),
                Write::Sampled(2, vec![(img(&NORMAL), near)]),
                Write::StorageImage(3, img(&GUIDE)),
            ],
        )?;
        let common = |set: [TargetDecl; 3]| {
            vec![
                Write::Buffer(0, shared.frame_ubo),
                Write::Sampled(1, vec![(img(&ALBEDO), near)]),
                Write::StorageImage(2, img(&GUIDE)),
                Write::StorageImage(3, img(&set[0])),
                Write::StorageImage(4, img(&set[1])),
                Write::StorageImage(5, img(&set[2])),
            ]
        };
        for (i, s) in self.signals.iter().enumerate() {
            self.variance.write_set(gpu, i, &common([s.target, SAMPLES, PING_PONG[0]]))?;
            for turn in 0..2 {
                let set = common([PING_PONG[turn], PING_PONG[1 - turn], s.output]);
                self.atrous.write_set(gpu, 2 * i + turn, &set)?;
            }
        }
        Ok(())
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        if self.signals.is_empty() {
            return;
        }
        let (w, h) = (ctx.images.width, ctx.images.height);
        ctx.images.access(
            ctx.rec,
            &[
                (DEPTH, Access::Read(Use::SAMPLED)),
                (NORMAL, Access::Read(Use::SAMPLED)),
                (GUIDE, Access::Write(Use::STORAGE)),
            ],
        );
        let first = self.constants(&self.signals[0], 0, 0);
        self.guide.dispatch(ctx.rec, bytemuck::bytes_of(&first), w, h);
        // A still camera's running mean holds the frames accumulated before this one and this
        // one; a reprojected history says per pixel.
        let samples = if self.reprojected { 0 } else { ctx.rt.accumulated + 1 };
        for (i, s) in self.signals.iter().enumerate() {
            ctx.images.access(
                ctx.rec,
                &[
                    (ALBEDO, Access::Read(Use::SAMPLED)),
                    (GUIDE, Access::Read(Use::STORAGE)),
                    (s.target, Access::Read(Use::STORAGE)),
                    (SAMPLES, Access::Read(Use::STORAGE)),
                    (PING_PONG[0], Access::Write(Use::STORAGE)),
                ],
            );
            let c = self.constants(s, samples, 0);
            self.variance.dispatch_set(ctx.rec, i, bytemuck::bytes_of(&c), w, h);
            for it in 0..self.filter.iterations {
                let turn = it as usize % 2;
                // Both images an iteration may write are bound (and so must be in the storage
                // layout), whichever it writes.
                ctx.images.access(
                    ctx.rec,
                    &[
                        (PING_PONG[turn], Access::Read(Use::STORAGE)),
                        (PING_PONG[1 - turn], Access::Write(Use::STORAGE)),
                        (s.output, Access::Write(Use::STORAGE)),
                    ],
                );
                let c = self.constants(s, samples, it);
                self.atrous.dispatch_set(ctx.rec, 2 * i + turn, bytemuck::bytes_of(&c), w, h);
            }
        }
    }
}
