//! Mitchell's god rays (`--media mitchell`, seed 002 §5): per light, an occlusion image at a
//! fraction of the screen's resolution (`shaders/mitchell/occlusion.comp`: 1 where the light's
//! emitter shows, 0 where an occluder does), then a radial blur of it from every pixel towards
//! the light's screen position, added to the radiance (`shaders/mitchell/blur.comp`). Cost is
//! linear in the lights, as in the seed; a light behind the camera gives no shafts (the
//! method's known failure, asserted by a test rather than hidden).

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

/// The seed's density (Fig. 3.6): the march covers 1/1.4 of the way to the light.
pub const DENSITY: f32 = 1.4;
/// The seed's decay per sample (Fig. 3.6): none.
pub const DECAY: f32 = 1.0;
/// Radius of a point or spot light's emitting sphere, as a fraction of the scene's
/// bounding-box diagonal (the seed's light-coloured cube around its point light).
pub const PROXY_RADIUS: f32 = 0.02;

/// One light's occlusion image.
pub const OCCLUSION: TargetDecl = TargetDecl {
    name: "mitchell occlusion",
    format: vk::Format::R16_SFLOAT,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
    ),
    array: false,
};

/// The pass.
#[derive(Debug)]
pub struct MitchellPass {
    occlusion: Kernel,
    blur: Kernel,
    constants: GodRayConstants,
    divisor: u32,
    /// Lights to blur towards (0 without a medium: the pass records nothing).
    lights: u32,
}

impl MitchellPass {
    /// Builds the pipelines: `samples` towards each light, the occlusion image at `resolution`,
    /// `exposure` the gain of a march that sees the emitter throughout.
    pub fn new(
        gpu: &Gpu,
        samples: u32,
        resolution: ScreenFraction,
        exposure: f32,
    ) -> PlayResult<MitchellPass> {
        use BindingKind::*;
        let push = std::mem::size_of::<GodRayConstants>() as u32;
        let [occlusion, blur] = Kernel::several(
            gpu,
            [
                (
                    &[
                        Binding::one(Uniform),
                        Binding::one(Storage),
                        Binding::one(Sampled),
                        Binding::one(StorageImage),
                    ],
                    spirv::shader!("mitchell/occlusion.comp"),
                ),
                (
                    &[
                        Binding::one(Uniform),
                        Binding::one(Storage),
                        Binding::one(Storage),
                        Binding::one(Sampled),
                        Binding::one(StorageImage),
                    ],
                    spirv::shader!("mitchell/blur.comp"),
                ),
            ],
            push,
        )?;
        let samples = samples.max(1);
        let constants = GodRayConstants {
            samples,
            step: DENSITY,
            gain: exposure / samples as f32,
            decay: DECAY,
            ..Default::default()
        };
        Ok(MitchellPass { occlusion, blur, constants, divisor: resolution.divisor(), lights: 0 })
    }
}

impl Pass for MitchellPass {
    fn name(&self) -> &'static str {
        "media"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        let d = self.divisor;
        vec![(OCCLUSION, OCCLUSION.sized(width.div_ceil(d), height.div_ceil(d), 1))]
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
        self.constants.extent = PROXY_RADIUS * shared.scene.diagonal();
        self.constants.media = m.count;
        let img = |t: &TargetDecl| shared.images.get(t).view;
        self.occlusion.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Buffer(1, shared.lights),
                Write::Sampled(2, vec![(img(&DEPTH), shared.scene.nearest_clamp)]),
                Write::StorageImage(3, img(&OCCLUSION)),
            ],
        )?;
        self.blur.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Buffer(1, shared.lights),
                Write::Buffer(2, &m.table),
                Write::Sampled(3, vec![(img(&OCCLUSION), shared.scene.linear_clamp)]),
                Write::StorageImage(4, img(&RADIANCE)),
            ],
        )
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let small = ctx.images.get(&OCCLUSION).desc;
        let (width, height) = (ctx.images.width, ctx.images.height);
        for light in 0..self.lights {
            let push = GodRayConstants { light, ..self.constants };
            ctx.images.access(
                ctx.rec,
                &[(DEPTH, Access::Read(Use::SAMPLED)), (OCCLUSION, Access::Write(Use::STORAGE))],
            );
            self.occlusion.dispatch(ctx.rec, bytemuck::bytes_of(&push), small.width, small.height);
            ctx.images.access(
                ctx.rec,
                &[(OCCLUSION, Access::Read(Use::SAMPLED)), (RADIANCE, Access::ReadWrite(Use::STORAGE))],
            );
            self.blur.dispatch(ctx.rec, bytemuck::bytes_of(&push), width, height);
        }
    }
}
