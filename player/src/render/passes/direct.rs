//! Direct light and composition (`shaders/lighting/direct.comp`): every analytic light over the
//! G-buffer (Lambert or Cook–Torrance GGX, multiple-scattering compensation from the baked
//! table), shadowed by the baked shadow maps (PCF; PCSS for rect lights) or by the ray-traced
//! layers, the constant sky through the split-sum table, ray-traced AO, reflections and GI
//! composited where they ran, the light dimmed by participating media when a media technique
//! runs; writes linear radiance.

use crate::gpu::vk;

use super::gbuffer::{ALBEDO, DEPTH, EMISSION, MATERIAL, NORMAL};
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared, ao, probes, rt_direct, rt_gi, rt_reflections, rt_shadows, see_through};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write};
use crate::render::graph::{Access, TargetDecl};
use crate::render::{MAX_SHADOW_MAPS, Techniques, spirv};
use kiln_format::gpu::FrameFlags;

/// Linear scene radiance (what `-o x.exr` writes).
pub const RADIANCE: TargetDecl = TargetDecl {
    name: "radiance",
    format: vk::Format::R32G32B32A32_SFLOAT,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::TRANSFER_SRC.as_raw(),
    ),
    array: false,
};

/// Bytes of `direct.comp`'s push constants: the dispatch's first pixel (`uvec2 origin`).
pub const PUSH_BYTES: u32 = 8;

/// What a specialization constant of `direct.comp` says may happen in the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpecInput {
    /// This frame flag may be set.
    Flag(u32),
    /// A media technique may dim the light reaching surfaces.
    Media,
    /// The scene has rect lights.
    RectLights,
}

/// The inputs of `direct.comp`'s specialization constants, by id from 1 (`DIRECT_*` there; each
/// a bool defaulting to true, so that a pipeline made without constants has every path).
pub const SPEC_INPUTS: [(SpecInput, &str); 9] = [
    (SpecInput::Flag(FrameFlags::RT_SHADOWS), "DIRECT_RT_SHADOWS"),
    (SpecInput::Flag(FrameFlags::RT_AO), "DIRECT_AO"),
    (SpecInput::Flag(FrameFlags::RT_REFLECTIONS), "DIRECT_RT_REFLECTIONS"),
    (SpecInput::Flag(FrameFlags::RT_GI | FrameFlags::SCREEN_GI), "DIRECT_GI"),
    (SpecInput::Flag(FrameFlags::SCREEN_REFLECTIONS), "DIRECT_SCREEN_REFLECTIONS"),
    (SpecInput::Media, "DIRECT_MEDIA"),
    (SpecInput::RectLights, "DIRECT_RECT_LIGHTS"),
    (SpecInput::Flag(FrameFlags::RT_DIRECT), "DIRECT_EMISSIVE"),
    (SpecInput::Flag(FrameFlags::PROBE_SPECULAR), "DIRECT_PROBE_SPECULAR"),
];

/// The G-buffer targets it samples, in binding order (6–10).
const GBUFFER: [TargetDecl; 5] = [DEPTH, NORMAL, ALBEDO, MATERIAL, EMISSION];

/// The ray-traced (and probe) results it composites and their bindings (the media table takes
/// 16, the environment 18–19).
const RAY_TRACED: [(TargetDecl, u32); 6] = [
    (rt_shadows::SHADOWS, 12),
    (ao::AO, 13),
    (rt_reflections::REFLECTIONS, 14),
    (rt_gi::GI, 15),
    (rt_direct::DIRECT, 17),
    (probes::SPECULAR, 20),
];

/// The direct-light pass: its kernel, the G-buffer it lights and the image it writes, and the
/// ray-traced images it reads, by binding (each signal's denoised image where the denoiser
/// filters it).
#[derive(Debug)]
pub struct DirectPass {
    kernel: Kernel,
    inputs: [(TargetDecl, u32); 6],
    gbuffer: [TargetDecl; 5],
    output: TargetDecl,
    name: &'static str,
}

impl DirectPass {
    /// Builds the pipeline, specialised for `techniques` (and rect lights or none): the code for
    /// inputs they never provide is left out, which halved the driver's cold compile of this
    /// pass on the H100 (docs/benchmarks/codec/auto-default).
    pub fn new(gpu: &Gpu, techniques: &Techniques, rect_lights: bool) -> PlayResult<DirectPass> {
        let constants = Self::constants(techniques.flags(), techniques.dims_surfaces(), rect_lights);
        let mut inputs = RAY_TRACED;
        for noisy in techniques.noisy() {
            for (t, _) in &mut inputs {
                if *t == noisy.target {
                    *t = noisy.output;
                }
            }
        }
        Self::make(gpu, &constants, inputs, GBUFFER, RADIANCE, "direct")
    }

    /// The same kernel over the see-through layer's G-buffer into its own image
    /// ([`see_through::RADIANCE`]): every screen-space and ray-traced input left out (they were
    /// made for the opaque surfaces behind it), so that the layer is lit by the analytic lights
    /// (shadowed by the shadow maps where the frame uses them, else unshadowed), the sky or
    /// environment through the split sum, and its emission; the media dim it as `media` says.
    pub fn see_through(gpu: &Gpu, media: bool, rect_lights: bool) -> PlayResult<DirectPass> {
        let constants = Self::constants(0, media, rect_lights);
        Self::make(
            gpu,
            &constants,
            RAY_TRACED,
            see_through::GBUFFER,
            see_through::RADIANCE,
            "see-through light",
        )
    }

    fn make(
        gpu: &Gpu,
        constants: &[u32],
        inputs: [(TargetDecl, u32); 6],
        gbuffer: [TargetDecl; 5],
        output: TargetDecl,
        name: &'static str,
    ) -> PlayResult<DirectPass> {
        let kernel = Kernel::specialized(
            gpu,
            &Self::bindings(),
            spirv::shader!("lighting/direct.comp"),
            PUSH_BYTES,
            constants,
        )?;
        Ok(DirectPass { kernel, inputs, gbuffer, output, name })
    }

    /// Specialization constants by id (`direct.comp`): 0 is unused (the texel decoders' id), then
    /// one boolean per input in [`SPEC_INPUTS`] order.
    pub fn constants(flags: u32, media: bool, rect_lights: bool) -> [u32; 1 + SPEC_INPUTS.len()] {
        let mut c = [0; 1 + SPEC_INPUTS.len()];
        for (i, (input, _)) in SPEC_INPUTS.iter().enumerate() {
            c[1 + i] = match input {
                SpecInput::Flag(f) => flags & f != 0,
                SpecInput::Media => media,
                SpecInput::RectLights => rect_lights,
            } as u32;
        }
        c
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
        bindings.push(Binding::one(StorageImage));
        bindings.extend([Binding::one(Storage); 2]);
        bindings.push(Binding::one(StorageImage));
        bindings
    }
}

impl Pass for DirectPass {
    fn name(&self) -> &'static str {
        self.name
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        vec![(self.output, self.output.sized(width, height, 1))]
    }

    fn binds(&self) -> Vec<TargetDecl> {
        self.gbuffer.iter().copied().chain(self.inputs.iter().map(|(t, _)| *t)).collect()
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
        for (i, t) in self.gbuffer.iter().enumerate() {
            writes.push(Write::Sampled(6 + i as u32, vec![(img(t), near)]));
        }
        writes.push(Write::StorageImage(11, img(&self.output)));
        for (t, binding) in &self.inputs {
            writes.push(Write::StorageImage(*binding, img(t)));
        }
        // The media table when a media technique uploaded it (the frame constants then count
        // its entries), else any storage buffer: no entry is read.
        writes.push(Write::Buffer(16, scene.media.as_ref().map_or(shared.lights, |m| &m.table)));
        writes.extend(scene.environment_writes(18)?);
        self.kernel.write(gpu, &writes)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let mut io = super::gbuffer::sampled(&self.gbuffer);
        io.extend(self.inputs.iter().map(|(t, _)| (*t, Access::Read(Use::STORAGE))));
        io.push((self.output, Access::Write(Use::STORAGE)));
        ctx.images.access(ctx.rec, &io);
        // The see-through layer is lit over its screen area alone; the frame everywhere.
        let area = if self.output == see_through::RADIANCE {
            ctx.see_through_area
        } else {
            vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: vk::Extent2D { width: ctx.images.width, height: ctx.images.height },
            }
        };
        let origin = [area.offset.x.max(0) as u32, area.offset.y.max(0) as u32];
        self.kernel.dispatch(ctx.rec, bytemuck::cast_slice(&origin), area.extent.width, area.extent.height);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shader's source declares exactly the constants `SPEC_INPUTS` sets, by name and id,
    /// each a bool defaulting to true (the SPIR-V's ids and defaults: `texels.rs`; the SPIR-V
    /// against the source: `tests/spirv.rs`).
    #[test]
    fn the_shaders_constants_are_the_ones_the_pass_sets() {
        let source = include_str!("../../../../shaders/lighting/direct.comp");
        let found: Vec<String> = source
            .lines()
            .filter(|l| l.contains("constant_id"))
            .map(|l| l.split_whitespace().collect::<Vec<_>>().join(" "))
            .collect();
        let expected: Vec<String> = SPEC_INPUTS
            .iter()
            .enumerate()
            .map(|(i, (_, name))| format!("layout(constant_id = {}) const bool {name} = true;", i + 1))
            .collect();
        assert_eq!(found, expected);
    }

    /// Each input's constant is on exactly when the frame may need it: every flag a set of
    /// techniques can raise keeps its code, and the default techniques keep only the shadow maps and
    /// the emissive triangles' light.
    #[test]
    fn constants_follow_the_flags_media_and_rect_lights() {
        let all = FrameFlags::RT_SHADOWS
            | FrameFlags::RT_AO
            | FrameFlags::RT_REFLECTIONS
            | FrameFlags::REFLECTIONS_HALF
            | FrameFlags::RT_GI
            | FrameFlags::SCREEN_GI
            | FrameFlags::SCREEN_REFLECTIONS
            | FrameFlags::RT_DIRECT
            | FrameFlags::PROBE_SPECULAR;
        assert_eq!(DirectPass::constants(all, true, true), [0, 1, 1, 1, 1, 1, 1, 1, 1, 1]);
        assert_eq!(DirectPass::constants(0, false, false), [0; 10]);
        assert_eq!(DirectPass::constants(FrameFlags::SCREEN_GI, false, true), [0, 0, 0, 0, 1, 0, 0, 1, 0, 0]);
        assert_eq!(DirectPass::constants(FrameFlags::RT_GI, true, false), [0, 0, 0, 0, 1, 0, 1, 0, 0, 0]);
        assert_eq!(
            DirectPass::constants(FrameFlags::RT_DIRECT, false, false),
            [0, 0, 0, 0, 0, 0, 0, 0, 1, 0]
        );
        assert_eq!(
            DirectPass::constants(FrameFlags::RT_GI | FrameFlags::PROBE_SPECULAR, false, false),
            [0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
        );
        let defaults = Techniques::default().flags();
        assert_eq!(
            DirectPass::constants(defaults, false, false),
            [0, 0, 0, 0, 0, 0, 0, 0, 1, 0],
            "default flags {defaults:#x}"
        );
    }
}
