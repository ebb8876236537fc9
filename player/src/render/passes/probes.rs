//! Diffuse GI from the compiler's irradiance probes (`--gi probes`; `shaders/probes/gi.comp`):
//! per pixel, the eight probes around the surface point, each weighted trilinearly, by how much
//! it lies in front of the surface, and by the Chebyshev test of its distance moments (a probe
//! that saw a wall nearer than the point is mostly cut off: no light through walls), give the
//! mean incoming radiance in place of the sky's ambient, as the ray-traced GI does
//! (`FrameFlags::RT_GI`). Deterministic, no history: the image is overwritten every frame. The
//! irradiance's emitted layer (emissive surfaces seen directly) is added only when the frame
//! has no direct light of emissive surfaces (`--direct none`). With the same weights it writes
//! the irradiance along each pixel's mirror direction ([`SPECULAR`]), the split sum's incoming
//! radiance where no reflection is traced or seen on screen (`FrameFlags::PROBE_SPECULAR`).

use kiln_format::gpu::ProbeConstants;

use super::gbuffer::{DEPTH, NORMAL};
use super::kernel::Kernel;
use super::rt_gi::GI;
use super::{FrameCtx, Pass, Shared};
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write, vk};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The probes' irradiance along each pixel's mirror direction (rgb; half floats: it lights
/// glossy surfaces, whose error the filtering already dwarfs).
pub const SPECULAR: TargetDecl = TargetDecl {
    name: "probe specular",
    format: vk::Format::R16G16B16A16_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The lookup point's default move along the surface normal, in probe spacings (`--gi probes`'
/// knob's default, and the reflections' hits', [`super::hybrid`]).
pub const NORMAL_BIAS: f32 = 0.1;
/// The lookup point's default move towards the viewer, in probe spacings.
pub const VIEW_BIAS: f32 = 0.2;

/// The G-buffer targets it samples, in binding order (1–2).
const GBUFFER: [TargetDecl; 2] = [DEPTH, NORMAL];

/// The probe GI pass.
#[derive(Debug)]
pub struct ProbesPass {
    kernel: Kernel,
    /// The biases along the normal and towards the camera, in spacings.
    bias: (f32, f32),
    constants: ProbeConstants,
}

impl ProbesPass {
    /// Builds the pipeline; the lookup point moves `normal_bias` spacings along the normal and
    /// `view_bias` towards the camera.
    pub fn new(gpu: &Gpu, normal_bias: f32, view_bias: f32) -> PlayResult<ProbesPass> {
        use BindingKind::*;
        let bindings = [
            Binding::one(Uniform),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(Storage),
            Binding::one(StorageImage),
            Binding::one(StorageImage),
        ];
        let push = std::mem::size_of::<ProbeConstants>() as u32;
        let kernel = Kernel::new(gpu, &bindings, spirv::shader!("probes/gi.comp"), push)?;
        Ok(ProbesPass { kernel, bias: (normal_bias, view_bias), constants: ProbeConstants::default() })
    }
}

impl Pass for ProbesPass {
    fn name(&self) -> &'static str {
        "probes"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(GI, GI.sized(width, height, 1)), (SPECULAR, SPECULAR.sized(width, height, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        GBUFFER.to_vec()
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let scene = shared.scene;
        let probes = scene.probes.as_ref().ok_or_else(|| {
            PlayError::new(Exit::BadInput, "--gi probes: the file's irradiance probes are not resident")
        })?;
        self.constants = probes.constants(self.bias.0, self.bias.1);
        let img = |t: &TargetDecl| shared.images.get(t).view;
        let mut writes = vec![Write::Buffer(0, shared.frame_ubo)];
        for (i, t) in GBUFFER.iter().enumerate() {
            writes.push(Write::Sampled(1 + i as u32, vec![(img(t), scene.nearest_clamp)]));
        }
        writes.extend([
            Write::Sampled(3, vec![(probes.irradiance.view, scene.linear_clamp)]),
            Write::Sampled(4, vec![(probes.visibility.view, scene.linear_clamp)]),
            Write::Buffer(5, &probes.states),
            Write::StorageImage(6, img(&GI)),
            Write::StorageImage(7, img(&SPECULAR)),
        ]);
        self.kernel.write(gpu, &writes)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let mut io = super::gbuffer::sampled(&GBUFFER);
        io.push((GI, Access::Write(Use::STORAGE)));
        io.push((SPECULAR, Access::Write(Use::STORAGE)));
        ctx.images.access(ctx.rec, &io);
        let push = bytemuck::bytes_of(&self.constants);
        self.kernel.dispatch(ctx.rec, push, ctx.images.width, ctx.images.height);
    }
}
