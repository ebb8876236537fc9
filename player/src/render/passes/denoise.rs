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
/// Per pixel: distance along its camera ray and packed normal (8 bytes a tap).
const GUIDE: TargetDecl = storage("denoise guide", vk::Format::R32G32_UINT);
/// The filter's two pairs of images (per signal of a pair: demodulated rgb, the noise's
/// standard deviation) in half floats, taking turns: half the bytes a tap reads of full floats.
const PING_PONG: [[TargetDecl; 2]; 2] = [
    [
        storage("denoise a0", vk::Format::R16G16B16A16_SFLOAT),
        storage("denoise a1", vk::Format::R16G16B16A16_SFLOAT),
    ],
    [
        storage("denoise b0", vk::Format::R16G16B16A16_SFLOAT),
        storage("denoise b1", vk::Format::R16G16B16A16_SFLOAT),
    ],
];

/// Signals filtered by one dispatch (the kernels' image arrays): each tap's geometry weight,
/// most of a tap's cost, serves both.
const PER_DISPATCH: usize = 2;

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
    /// Depth edge-stopping in pixel footprints.
    pub sigma_plane: f32,
    /// Taps an iteration along each axis: 5 (SVGF's B3 spline) or 3 (the linear B-spline).
    pub taps: u32,
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
        let pairs = Binding { kind: StorageImage, count: PER_DISPATCH as u32 };
        let variance: &[Binding] = &[
            Binding::one(Uniform),
            Binding::one(Sampled),
            Binding::one(StorageImage),
            pairs,
            Binding::one(StorageImage),
            pairs,
        ];
        let atrous: &[Binding] =
            &[Binding::one(Uniform), Binding::one(Sampled), Binding::one(StorageImage), pairs, pairs, pairs];
        let push = std::mem::size_of::<DenoiseConstants>() as u32;
        let [guide, variance, atrous] = Kernel::several(
            gpu,
            [
                (guide, spirv::shader!("denoise/guide.comp")),
                (variance, spirv::shader!("denoise/variance.comp")),
                (
                    atrous,
                    if filter.taps == 3 {
                        spirv::shader!("denoise/atrous3.comp")
                    } else {
                        spirv::shader!("denoise/atrous.comp")
                    },
                ),
            ],
            push,
        )?;
        let filter = Filter { iterations: filter.iterations.max(1), ..filter };
        Ok(DenoisePass { guide, variance, atrous, signals, filter, reprojected })
    }

    fn constants(&self, group: &[Noisy], samples: u32, iteration: u32) -> DenoiseConstants {
        DenoiseConstants {
            signals: group.len() as u32,
            samples,
            step: 1 << iteration,
            demodulate: group.iter().enumerate().map(|(i, s)| (s.demodulate as u32) << i).sum(),
            last: (iteration + 1 == self.filter.iterations) as u32,
            sigma_luminance: self.filter.sigma_luminance,
            sigma_normal: self.filter.sigma_normal,
            sigma_plane: self.filter.sigma_plane,
        }
    }
}

/// A group's images at one binding: `pick` of each signal, the first repeated where the group
/// has one signal (that slot is never read).
fn pair(group: &[Noisy], pick: impl Fn(usize, &Noisy) -> TargetDecl) -> [TargetDecl; 2] {
    let first = pick(0, &group[0]);
    [first, group.get(1).map_or(first, |s| pick(1, s))]
}

impl Pass for DenoisePass {
    fn name(&self) -> &'static str {
        "denoise"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let mut made: Vec<TargetDecl> = vec![GUIDE];
        let [a, b] = PING_PONG;
        made.extend(a.into_iter().zip(b).take(self.signals.len()).flat_map(|(a, b)| [a, b]));
        made.extend(self.signals.iter().map(|s| s.output));
        made.into_iter().map(|t| (t, t.sized(width, height, 1))).collect()
    }

    fn binds(&self) -> Vec<TargetDecl> {
        let mut b = vec![DEPTH, NORMAL, ALBEDO, SAMPLES];
        b.extend(self.signals.iter().map(|s| s.target));
        b
    }

    fn bind<'a>(&mut self, gpu: &Gpu, shared: &Shared<'a>) -> PlayResult {
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
        let views =
            |binding: u32, t: [TargetDecl; 2]| Write::StorageImages(binding, t.iter().map(img).collect());
        // Bindings 0-2 are the same in both kernels' sets; 3-5 are the group's images.
        let set = |rest: [Write<'a>; 3]| -> Vec<Write<'a>> {
            [
                Write::Buffer(0, shared.frame_ubo),
                Write::Sampled(1, vec![(img(&ALBEDO), near)]),
                Write::StorageImage(2, img(&GUIDE)),
            ]
            .into_iter()
            .chain(rest)
            .collect()
        };
        for (g, group) in self.signals.chunks(PER_DISPATCH).enumerate() {
            let noisy = pair(group, |_, s| s.target);
            let first = pair(group, |i, _| PING_PONG[0][i]);
            let samples = Write::StorageImage(4, img(&SAMPLES));
            self.variance.write_set(gpu, g, &set([views(3, noisy), samples, views(5, first)]))?;
            for turn in 0..2 {
                let src = pair(group, |i, _| PING_PONG[turn][i]);
                let dst = pair(group, |i, _| PING_PONG[1 - turn][i]);
                let out = pair(group, |_, s| s.output);
                self.atrous.write_set(
                    gpu,
                    2 * g + turn,
                    &set([views(3, src), views(4, dst), views(5, out)]),
                )?;
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
        let first = self.constants(&self.signals[..1], 0, 0);
        self.guide.dispatch(ctx.rec, bytemuck::bytes_of(&first), w, h);
        // A still camera's running mean holds the frames accumulated before this one and this
        // one; a reprojected history says per pixel.
        let samples = if self.reprojected { 0 } else { ctx.rt.accumulated + 1 };
        for (g, group) in self.signals.chunks(PER_DISPATCH).enumerate() {
            let mut io = vec![
                (ALBEDO, Access::Read(Use::SAMPLED)),
                (GUIDE, Access::Read(Use::STORAGE)),
                (SAMPLES, Access::Read(Use::STORAGE)),
            ];
            for (i, s) in group.iter().enumerate() {
                io.push((s.target, Access::Read(Use::STORAGE)));
                io.push((PING_PONG[0][i], Access::Write(Use::STORAGE)));
            }
            ctx.images.access(ctx.rec, &io);
            let c = self.constants(group, samples, 0);
            self.variance.dispatch_set(ctx.rec, g, bytemuck::bytes_of(&c), w, h);
            for it in 0..self.filter.iterations {
                let turn = it as usize % 2;
                // Every image an iteration may write is bound (and so must be in the storage
                // layout), whichever it writes.
                let mut io = Vec::new();
                for (i, s) in group.iter().enumerate() {
                    io.push((PING_PONG[turn][i], Access::Read(Use::STORAGE)));
                    io.push((PING_PONG[1 - turn][i], Access::Write(Use::STORAGE)));
                    io.push((s.output, Access::Write(Use::STORAGE)));
                }
                ctx.images.access(ctx.rec, &io);
                let c = self.constants(group, samples, it);
                self.atrous.dispatch_set(ctx.rec, 2 * g + turn, bytemuck::bytes_of(&c), w, h);
            }
        }
    }
}
