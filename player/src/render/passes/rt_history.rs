//! Reprojected accumulation of the ray-traced passes (`--aa taa` with `--shadows rt`, `--ao
//! rt`, `--reflections rt`, `--gi rt`; `shaders/history/`): instead of restarting their running
//! mean whenever the camera moves, each target's history follows its surface points.
//!
//! The passes then write this frame's sample only (their push constants say no frame was
//! accumulated), and this pass, after them:
//! 1. `motion.comp`: per pixel, where its surface point was last frame and how many frames of
//!    history it has there (0 where it was disoccluded: the previous frame's depth shows another
//!    surface there; capped at the `--taa-frames` while the camera moves);
//! 2. `blend_*.comp`, per target: the sample blended into the target's history read at that
//!    point (1/(n + 1) after n frames), written to the target (which the direct pass reads) and
//!    kept as the next frame's history.
//!
//! Every history comes in two images that take turns (frame n reads what frame n − 1 wrote), as
//! do the motion and depth images.

use super::gbuffer::DEPTH;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

const SAMPLED_STORAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
);

const fn image(name: &'static str, format: vk::Format, array: bool) -> TargetDecl {
    TargetDecl { name, format, usage: SAMPLED_STORAGE, array }
}

/// Per pixel: its point's position last frame (pixels) and its frames of history.
const MOTION: [TargetDecl; 2] = [
    image("rt motion a", vk::Format::R32G32B32A32_SFLOAT, false),
    image("rt motion b", vk::Format::R32G32B32A32_SFLOAT, false),
];
/// Per pixel: the samples in its running mean after this frame's blend (read by the denoiser).
pub const SAMPLES: TargetDecl = image("rt samples", vk::Format::R32_SFLOAT, false);
/// The depth each frame's motion was made at.
const DEPTHS: [TargetDecl; 2] =
    [image("rt depth a", vk::Format::R32_SFLOAT, false), image("rt depth b", vk::Format::R32_SFLOAT, false)];

/// Which blend kernel a target takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A layered one-channel target (a layer per light).
    Layers,
    /// A one-channel target.
    One,
    /// A four-channel target.
    Four,
}

/// One accumulated target and its two histories: what a ray-traced technique hands this pass
/// (`Technique::accumulated`).
#[derive(Debug, Clone, Copy)]
pub struct Accumulated {
    target: TargetDecl,
    histories: [TargetDecl; 2],
    kind: Kind,
    /// Screen pixels per texel along each axis.
    step: u32,
    layers: u32,
}

impl Accumulated {
    /// `target`, blended by the kernel of `kind`, with histories named `histories`, one texel
    /// per `step` × `step` pixels, `layers` layers.
    pub fn new(
        target: TargetDecl,
        histories: [&'static str; 2],
        kind: Kind,
        step: u32,
        layers: u32,
    ) -> Accumulated {
        let history = |name| TargetDecl { name, usage: SAMPLED_STORAGE, ..target };
        Accumulated { target, histories: histories.map(history), kind, step, layers }
    }
}

/// Push constants of the blend kernels.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BlendPush {
    step: u32,
    layers: u32,
}

/// The pass.
#[derive(Debug)]
pub struct RtHistoryPass {
    motion: Kernel,
    /// Blend kernels by [`Kind`] (Layers, One, Four).
    blends: [Kernel; 3],
    targets: Vec<Accumulated>,
    cap: f32,
    /// Which image of each pair this frame writes.
    turn: usize,
}

impl RtHistoryPass {
    /// The pass for the ray-traced `targets`, in the order given, histories capped at `cap`
    /// frames while the camera moves.
    pub fn new(gpu: &Gpu, targets: Vec<Accumulated>, cap: u32) -> PlayResult<RtHistoryPass> {
        use BindingKind::*;
        let blend: &[Binding] = &[
            Binding::one(Uniform),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
            Binding::one(Sampled),
            Binding::one(StorageImage),
        ];
        let motion_bindings: &[Binding] = &[
            Binding::one(Uniform),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
        ];
        let push = std::mem::size_of::<BlendPush>() as u32;
        let [motion, layers, one, four] = Kernel::several(
            gpu,
            [
                (motion_bindings, spirv::shader!("history/motion.comp")),
                (blend, spirv::shader!("history/blend_layers.comp")),
                (blend, spirv::shader!("history/blend_r.comp")),
                (blend, spirv::shader!("history/blend_rgba.comp")),
            ],
            push,
        )?;
        Ok(RtHistoryPass { motion, blends: [layers, one, four], targets, cap: cap.max(1) as f32, turn: 0 })
    }

    fn blend(&self, kind: Kind) -> &Kernel {
        &self.blends[kind as usize]
    }

    /// The set of `target` (index into `targets`) for `turn` in its kernel.
    fn set_of(&self, target: usize, turn: usize) -> usize {
        let kind = self.targets[target].kind;
        2 * self.targets[..target].iter().filter(|t| t.kind == kind).count() + turn
    }
}

impl Pass for RtHistoryPass {
    fn name(&self) -> &'static str {
        "rt history"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let mut made: Vec<(TargetDecl, ImageDesc)> =
            MOTION.iter().chain(&DEPTHS).chain([&SAMPLES]).map(|t| (*t, t.sized(width, height, 1))).collect();
        for a in &self.targets {
            let (w, h) = (width.div_ceil(a.step), height.div_ceil(a.step));
            made.extend(a.histories.iter().map(|t| (*t, t.sized(w, h, a.layers))));
        }
        made
    }

    fn binds(&self) -> Vec<TargetDecl> {
        let mut b = vec![DEPTH];
        b.extend(self.targets.iter().map(|a| a.target));
        b
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let img = |t: &TargetDecl| shared.images.get(t).view;
        let (near, linear) = (shared.scene.nearest_clamp, shared.scene.linear_clamp);
        for turn in 0..2 {
            self.motion.write_set(
                gpu,
                turn,
                &[
                    Write::Buffer(0, shared.frame_ubo),
                    Write::Sampled(1, vec![(img(&DEPTH), near)]),
                    Write::Sampled(2, vec![(img(&DEPTHS[1 - turn]), near)]),
                    Write::Sampled(3, vec![(img(&MOTION[1 - turn]), near)]),
                    Write::StorageImage(4, img(&MOTION[turn])),
                    Write::StorageImage(5, img(&DEPTHS[turn])),
                    Write::StorageImage(6, img(&SAMPLES)),
                ],
            )?;
            for i in 0..self.targets.len() {
                let a = self.targets[i];
                let set = self.set_of(i, turn);
                self.blends[a.kind as usize].write_set(
                    gpu,
                    set,
                    &[
                        Write::Buffer(0, shared.frame_ubo),
                        Write::StorageImage(1, img(&MOTION[turn])),
                        Write::StorageImage(2, img(&a.target)),
                        Write::Sampled(3, vec![(img(&a.histories[1 - turn]), linear)]),
                        Write::StorageImage(4, img(&a.histories[turn])),
                    ],
                )?;
            }
        }
        // New images hold nothing: the renderer marks the first frame after a resize as
        // without history.
        self.turn = 0;
        Ok(())
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let (now, before) = (self.turn, 1 - self.turn);
        ctx.images.access(
            ctx.rec,
            &[
                (DEPTH, Access::Read(Use::SAMPLED)),
                (DEPTHS[before], Access::Read(Use::SAMPLED)),
                (MOTION[before], Access::Read(Use::SAMPLED)),
                (MOTION[now], Access::Write(Use::STORAGE)),
                (DEPTHS[now], Access::Write(Use::STORAGE)),
                (SAMPLES, Access::Write(Use::STORAGE)),
            ],
        );
        let (w, h) = (ctx.images.width, ctx.images.height);
        self.motion.dispatch_set(ctx.rec, now, bytemuck::bytes_of(&self.cap), w, h);
        for (i, a) in self.targets.iter().enumerate() {
            ctx.images.access(
                ctx.rec,
                &[
                    (MOTION[now], Access::Read(Use::STORAGE)),
                    (a.target, Access::ReadWrite(Use::STORAGE)),
                    (a.histories[before], Access::Read(Use::SAMPLED)),
                    (a.histories[now], Access::Write(Use::STORAGE)),
                ],
            );
            let push = BlendPush { step: a.step, layers: a.layers };
            let set = self.set_of(i, now);
            self.blend(a.kind).dispatch_set(
                ctx.rec,
                set,
                bytemuck::bytes_of(&push),
                w.div_ceil(a.step),
                h.div_ceil(a.step),
            );
        }
        self.turn = before;
    }
}
