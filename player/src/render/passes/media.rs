//! Participating media by ray marching (`shaders/media/march.comp`): each pixel's view ray,
//! from the camera to its surface (or out of the medium), is cut into steps inside every medium
//! box it crosses; each step adds the single-scattered light of every light (Henyey–Greenstein
//! phase, the light's visibility from the compiler's baked volume, trilinear, its transmittance
//! through the box analytic) times the transmittance to the camera integrated exactly over the
//! step, and the surface behind is dimmed by the box's transmittance. World space throughout, so
//! it holds with the light off screen or behind the camera, where image-space god rays fail.

use kiln_format::gpu::MarchConstants;

use super::direct::RADIANCE;
use super::gbuffer::DEPTH;
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, Use, Write};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The ray-marched media pass.
#[derive(Debug)]
pub struct MediaMarchPass {
    kernel: Kernel,
    constants: MarchConstants,
    /// Whether the scene has media (set when bound; without, the pass records nothing).
    active: bool,
}

impl MediaMarchPass {
    /// Builds the pipeline for `steps` steps through each medium.
    pub fn new(gpu: &Gpu, steps: u32) -> PlayResult<MediaMarchPass> {
        use BindingKind::*;
        let bindings = [
            Binding::one(Uniform),
            Binding::one(Storage),
            Binding::one(Storage),
            Binding::one(Storage),
            Binding::one(Storage),
            Binding::one(Sampled),
            Binding::one(StorageImage),
            Binding::one(Storage),
            Binding::one(Storage),
        ];
        let kernel = Kernel::new(
            gpu,
            &bindings,
            spirv::shader!("media/march.comp"),
            std::mem::size_of::<MarchConstants>() as u32,
        )?;
        let constants = MarchConstants { steps, ..Default::default() };
        Ok(MediaMarchPass { kernel, constants, active: false })
    }
}

impl Pass for MediaMarchPass {
    fn name(&self) -> &'static str {
        "media"
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![DEPTH, RADIANCE]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let Some(m) = &shared.scene.media else {
            self.active = false;
            return Ok(());
        };
        self.active = m.count > 0;
        self.constants = MarchConstants {
            steps: self.constants.steps,
            media: m.count,
            volume_medium: m.volume_medium,
            dims_x: m.dims[0],
            dims_y: m.dims[1],
            dims_z: m.dims[2],
            lights: m.lights,
            sky_volume: m.sky_volume,
        };
        let img = |t: &TargetDecl| shared.images.get(t).view;
        let mut writes = vec![
            Write::Buffer(0, shared.frame_ubo),
            Write::Buffer(1, shared.lights),
            Write::Buffer(2, &m.table),
            Write::Buffer(3, &m.volumes),
            Write::Buffer(4, &m.volume_of),
            Write::Sampled(5, vec![(img(&DEPTH), shared.scene.nearest_clamp)]),
            Write::StorageImage(6, img(&RADIANCE)),
        ];
        // The environment's harmonics light the media with the sky (bindings 7-8).
        writes.extend(shared.scene.environment_writes(7)?);
        self.kernel.write(gpu, &writes)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        if !self.active {
            return;
        }
        ctx.images.access(
            ctx.rec,
            &[(DEPTH, Access::Read(Use::SAMPLED)), (RADIANCE, Access::ReadWrite(Use::STORAGE))],
        );
        self.kernel.dispatch(
            ctx.rec,
            bytemuck::bytes_of(&self.constants),
            ctx.images.width,
            ctx.images.height,
        );
    }
}
