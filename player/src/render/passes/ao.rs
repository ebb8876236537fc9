//! The ambient-occlusion image the direct-light pass multiplies the sky's ambient by (when
//! `FrameFlags::RT_AO` is set), made by whichever AO technique runs: the ray-traced pass
//! ([`super::rt_ao`], a running mean) or a screen-space one (`--ao sao`, `--ao gtao`),
//! and the screen-space techniques' pass, [`ScreenAoPass`]: its estimator, then a bilateral blur with depth
//! weights that also upsamples a half-resolution result (`shaders/ao/blur.comp`).

use kiln_format::gpu::ScreenAoConstants;

use super::depth_pyramid::PYRAMID;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// An AO technique's radius (the ray length, the screen-space samples' world radius): in scene units, or as a fraction of the scene's diagonal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Radius {
    /// In scene units; `None`: `reach` times the scene's bounding-box diagonal.
    pub radius: Option<f32>,
    /// As a fraction of the scene's bounding-box diagonal (when `radius` is `None`); for rays,
    /// values ≥ 10 make every hit occlude fully: the sky's visibility.
    pub reach: f32,
}

impl Radius {
    /// In scene units, for a scene of bounding-box diagonal `diagonal`.
    pub fn world(&self, diagonal: f32) -> f32 {
        self.radius.unwrap_or(self.reach * diagonal)
    }
}

/// Ambient openness in [0, 1] per screen pixel (1: nothing occludes).
pub const AO: TargetDecl = TargetDecl {
    name: "ao",
    format: vk::Format::R32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// A screen-space technique's unblurred result: (openness, camera depth) per AO pixel.
pub const RAW: TargetDecl = TargetDecl {
    name: "ao raw",
    format: vk::Format::R32G32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The targets of a screen-space technique computing one AO pixel per `step` × `step` screen
/// pixels: its raw image and the AO image.
fn targets(width: u32, height: u32, step: u32) -> Vec<(TargetDecl, ImageDesc)> {
    vec![(RAW, RAW.sized(width.div_ceil(step), height.div_ceil(step), 1)), (AO, AO.sized(width, height, 1))]
}

/// The bindings of a screen-space AO kernel (`shaders/sao/sao.comp`, `shaders/gtao/gtao.comp`):
/// frame constants, G-buffer normal, depth pyramid, raw image.
const ESTIMATOR_BINDINGS: [Binding; 4] = [
    Binding::one(BindingKind::Uniform),
    Binding::one(BindingKind::Sampled),
    Binding::one(BindingKind::StorageImage),
    Binding::one(BindingKind::StorageImage),
];

/// Points a screen-space AO kernel at the frame's images (see [`ESTIMATOR_BINDINGS`]).
fn bind_estimator(kernel: &mut Kernel, gpu: &Gpu, shared: &Shared) -> PlayResult {
    let img = |t: &TargetDecl| shared.images.get(t).view;
    kernel.write(
        gpu,
        &[
            Write::Buffer(0, shared.frame_ubo),
            Write::Sampled(1, vec![(img(&super::gbuffer::NORMAL), shared.scene.nearest_clamp)]),
            Write::StorageImage(2, img(&PYRAMID)),
            Write::StorageImage(3, img(&RAW)),
        ],
    )
}

/// A screen-space AO pass (`--ao sao`, `--ao gtao`): its estimator kernel, then the
/// blur.
#[derive(Debug)]
pub struct ScreenAoPass {
    estimator: Kernel,
    blur: Kernel,
    constants: ScreenAoConstants,
    radius: Radius,
}

impl ScreenAoPass {
    /// The estimator from `spirv` and the blur, with `constants` (`step` the AO pixel's side in
    /// screen pixels; the radius is set from `technique` when bound).
    pub fn new(
        gpu: &Gpu,
        spirv: &[u8],
        constants: ScreenAoConstants,
        radius: Radius,
    ) -> PlayResult<ScreenAoPass> {
        use BindingKind::*;
        let push = std::mem::size_of::<ScreenAoConstants>() as u32;
        let [estimator, blur] = Kernel::several(
            gpu,
            [
                (&ESTIMATOR_BINDINGS, spirv),
                (
                    &[
                        Binding::one(Uniform),
                        Binding::one(StorageImage),
                        Binding::one(StorageImage),
                        Binding::one(StorageImage),
                    ],
                    spirv::shader!("ao/blur.comp"),
                ),
            ],
            push,
        )?;
        Ok(ScreenAoPass { estimator, blur, constants, radius })
    }
}

impl Pass for ScreenAoPass {
    fn name(&self) -> &'static str {
        "ao"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        targets(width, height, self.constants.step)
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![super::gbuffer::NORMAL, PYRAMID]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.constants.radius = self.radius.world(shared.scene.diagonal()).max(1e-6);
        bind_estimator(&mut self.estimator, gpu, shared)?;
        let img = |t: &TargetDecl| shared.images.get(t).view;
        self.blur.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::StorageImage(1, img(&PYRAMID)),
                Write::StorageImage(2, img(&RAW)),
                Write::StorageImage(3, img(&AO)),
            ],
        )
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let push = bytemuck::bytes_of(&self.constants);
        let raw = ctx.images.get(&RAW).desc;
        ctx.images.access(
            ctx.rec,
            &[
                (super::gbuffer::NORMAL, Access::Read(Use::SAMPLED)),
                (PYRAMID, Access::Read(Use::STORAGE)),
                (RAW, Access::Write(Use::STORAGE)),
            ],
        );
        self.estimator.dispatch(ctx.rec, push, raw.width, raw.height);
        ctx.images.access(
            ctx.rec,
            &[
                (PYRAMID, Access::Read(Use::STORAGE)),
                (RAW, Access::Read(Use::STORAGE)),
                (AO, Access::Write(Use::STORAGE)),
            ],
        );
        self.blur.dispatch(ctx.rec, push, ctx.images.width, ctx.images.height);
    }
}
