//! Direct light and composition (`shaders/lighting/direct.comp`): every analytic light over the
//! G-buffer (Lambert or Cook–Torrance GGX, multiple-scattering compensation from the baked
//! table), shadowed by the baked shadow maps (PCF; PCSS for rect lights) or by the ray-traced
//! layers, the constant sky through the split-sum table, ray-traced AO, reflections and GI
//! composited where they ran, the light dimmed by participating media when a media technique
//! runs; writes linear radiance.

use crate::gpu::vk;

use super::gbuffer::{ALBEDO, DEPTH, EMISSION, MATERIAL, NORMAL};
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared, ao, rt_gi, rt_reflections, rt_shadows};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write};
use crate::render::graph::{Access, TargetDecl};
use crate::render::{MAX_SHADOW_MAPS, spirv};

/// Linear scene radiance (what `-o x.exr` writes).
pub const RADIANCE: TargetDecl = TargetDecl {
    name: "radiance",
    format: vk::Format::R32G32B32A32_SFLOAT,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::TRANSFER_SRC.as_raw(),
    ),
    array: false,
};

/// The G-buffer targets it samples, in binding order (6–10).
const GBUFFER: [TargetDecl; 5] = [DEPTH, NORMAL, ALBEDO, MATERIAL, EMISSION];

/// The ray-traced results it composites, in binding order (12–15).
const RAY_TRACED: [TargetDecl; 4] = [rt_shadows::SHADOWS, ao::AO, rt_reflections::REFLECTIONS, rt_gi::GI];

/// The direct-light pass.
#[derive(Debug)]
pub struct DirectPass(Kernel);

impl DirectPass {
    /// Builds the pipeline.
    pub fn new(gpu: &Gpu) -> PlayResult<DirectPass> {
        Ok(DirectPass(Kernel::new(gpu, &Self::bindings(), spirv::DIRECT, 0)?))
    }

    /// The bindings of `direct.comp`, in order.
    pub fn bindings() -> Vec<Binding> {
        use BindingKind::*;
        let maps = Binding { kind: Sampled, count: MAX_SHADOW_MAPS as u32 };
        let mut bindings = vec![Binding::one(Uniform), Binding::one(Storage), Binding::one(Storage)];
        bindings.extend([Binding::one(Sampled), maps, maps]);
        bindings.extend([Binding::one(Sampled); 5]);
        bindings.extend([Binding::one(StorageImage); 5]);
        bindings.push(Binding::one(Storage));
        bindings
    }
}

impl Pass for DirectPass {
    fn name(&self) -> &'static str {
        "direct"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(RADIANCE, RADIANCE.sized(width, height, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        GBUFFER.iter().chain(&RAY_TRACED).copied().collect()
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let (scene, dummies) = (shared.scene, shared.dummies);
        let near = scene.nearest_clamp;
        let lut = scene.brdf_lut.as_ref().map_or(dummies.white.view, |i| i.view);
        let (maps_2d, maps_cube) = super::shadow_map_arrays(shared);
        let img = |t: &TargetDecl| shared.images.get(t).view;
        let mut writes = vec![
            Write::Buffer(0, shared.frame_ubo),
            Write::Buffer(1, shared.lights),
            Write::Buffer(2, shared.shadows),
            Write::Sampled(3, vec![(lut, scene.linear_clamp)]),
            Write::Sampled(4, maps_2d),
            Write::Sampled(5, maps_cube),
        ];
        for (i, t) in GBUFFER.iter().enumerate() {
            writes.push(Write::Sampled(6 + i as u32, vec![(img(t), near)]));
        }
        writes.push(Write::StorageImage(11, img(&RADIANCE)));
        for (i, t) in RAY_TRACED.iter().enumerate() {
            writes.push(Write::StorageImage(12 + i as u32, img(t)));
        }
        // The media table when a media technique uploaded it (the frame constants then count
        // its entries), else any storage buffer: no entry is read.
        writes.push(Write::Buffer(16, scene.media.as_ref().map_or(shared.lights, |m| &m.table)));
        self.0.write(gpu, &writes)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let mut io = super::gbuffer::sampled(&GBUFFER);
        io.extend(RAY_TRACED.iter().map(|t| (*t, Access::Read(Use::STORAGE))));
        io.push((RADIANCE, Access::Write(Use::STORAGE)));
        ctx.images.access(ctx.rec, &io);
        self.0.dispatch(ctx.rec, &[], ctx.images.width, ctx.images.height);
    }

    fn destroy(&mut self, gpu: &Gpu) {
        self.0.destroy(gpu);
    }
}
