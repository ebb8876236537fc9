//! The binding table every ray-traced pass of the hybrid pipeline shares
//! (`shaders/rt/hybrid.glsl`): the frame constants, the scene as the traversal and shading read
//! it, the G-buffer, every ray-traced target (those of passes that are off are 1 × 1
//! placeholders), the emitter table of next-event estimation and the emissive triangles' table of
//! the direct light of emissive surfaces, the environment and the irradiance probes (placeholders
//! where the file has none). Each pass has its own set of this layout.

use crate::gpu::vk;
use gpu_allocator::MemoryLocation;
use kiln_format::gpu::{ProbeConstants, RtConstants};

use super::gbuffer::{ALBEDO, MATERIAL, NORMAL, TRIANGLE};
use super::{FrameCtx, Shared, ao, probes, rt_direct, rt_gi, rt_reflections, rt_shadows};
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Gpu, SetLayout, Write};
use crate::render::TexelDecode;
use crate::render::graph::{Access, TargetDecl};
use crate::scene::bindings as scene_bindings;
use crate::scene::linespace::LineSpaceBuffers;

/// The first of the line space's bindings (`LS_BINDING` in the line-space kernels).
pub const LINE_SPACE_BINDING: u32 = 36;

/// The first of the irradiance probes' four bindings (`shaders/rt/hybrid.glsl`): their
/// constants, the irradiance and visibility atlases, the probes' states.
pub const PROBE_BINDING: u32 = 32;

/// The first of the environment's two bindings (`ENV_BINDING` in `shaders/rt/hybrid.glsl`).
pub const ENVIRONMENT_BINDING: u32 = 30;

/// The G-buffer targets the ray-traced passes sample.
pub const GBUFFER_READS: [TargetDecl; 4] = [TRIANGLE, NORMAL, ALBEDO, MATERIAL];

/// Every target the table binds.
pub fn bound() -> Vec<TargetDecl> {
    let mut t = GBUFFER_READS.to_vec();
    t.extend([rt_shadows::SHADOWS, ao::AO]);
    t.extend(rt_reflections::TARGETS);
    t.push(rt_gi::GI);
    t.extend(rt_direct::TARGETS);
    t
}

/// A set of the shared layout and one or more compute pipelines over it (the layout and its set
/// released when dropped).
#[derive(Debug)]
pub struct HybridSet {
    layout: SetLayout,
    /// How the pipelines over it decode the texel buffer.
    decode: TexelDecode,
    /// Whether the layout ends with the line space's bindings (at [`LINE_SPACE_BINDING`]).
    line_space: bool,
    /// The probes' constants (`ProbeConstants`, uniform; zero dimensions without probes).
    probe_constants: Buffer,
    /// The set (allocated by the first [`HybridSet::bind`]).
    pub set: vk::DescriptorSet,
}

impl HybridSet {
    /// The layout; with `line_space`, followed by the line space's bindings. Its pipelines
    /// decode the texel buffer as `decode` says.
    pub fn new(gpu: &Gpu, line_space: bool, decode: TexelDecode) -> PlayResult<HybridSet> {
        use BindingKind::*;
        let mut bindings = vec![Binding::one(Uniform)];
        bindings.extend([Binding::one(Storage); 11]);
        bindings.extend([Binding::one(Sampled); 4]);
        bindings.extend([Binding::one(StorageImage); 6]);
        bindings.extend([Binding::one(Storage); 2]);
        bindings.push(Binding::one(StorageImage));
        bindings.push(Binding::one(Storage));
        bindings.extend([Binding::one(StorageImage); 4]);
        bindings.extend([Binding::one(Storage); 2]);
        debug_assert_eq!(bindings.len() as u32, PROBE_BINDING);
        bindings.extend([
            Binding::one(Uniform),
            Binding::one(Sampled),
            Binding::one(Sampled),
            Binding::one(Storage),
        ]);
        debug_assert_eq!(bindings.len() as u32, LINE_SPACE_BINDING);
        if line_space {
            bindings.extend(LineSpaceBuffers::bindings());
        }
        let probe_constants = Buffer::new(
            gpu,
            "probe constants",
            std::mem::size_of::<ProbeConstants>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        Ok(HybridSet {
            layout: SetLayout::new(gpu, &bindings, 1)?,
            decode,
            line_space,
            probe_constants,
            set: vk::DescriptorSet::null(),
        })
    }

    /// A compute pipeline over this layout with the ray-traced passes' push constants,
    /// specialized for the set's texel decode.
    pub fn pipeline(&self, gpu: &Gpu, spirv: &[u8]) -> PlayResult<ComputePipeline> {
        ComputePipeline::specialized(
            gpu,
            spirv,
            &[&self.layout],
            std::mem::size_of::<RtConstants>() as u32,
            &self.decode.constants(),
        )
    }

    /// Allocates (once) and writes the set.
    pub fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let scene = shared.scene;
        let (Some(common), Some(r)) = (scene.ray_writes(), &scene.reference) else {
            return Err(PlayError::new(
                Exit::Gpu,
                "the ray-traced passes need the BVH, which was not uploaded",
            ));
        };
        if self.set == vk::DescriptorSet::null() {
            self.set = self.layout.allocate(gpu)?;
        }
        let img = |t: &TargetDecl| shared.images.get(t).view;
        let sampled = |t: &TargetDecl| vec![(img(t), scene.nearest_clamp)];
        let mut writes = vec![Write::Buffer(0, shared.frame_ubo)];
        writes.extend(common);
        writes.extend([
            Write::Buffer(scene_bindings::LIGHTS.binding, shared.lights),
            Write::Buffer(9, &r.texels),
            Write::Buffer(10, &r.textures),
            Write::Buffer(11, &scene.indices),
            Write::Sampled(12, sampled(&TRIANGLE)),
            Write::Sampled(13, sampled(&NORMAL)),
            Write::Sampled(14, sampled(&ALBEDO)),
            Write::Sampled(15, sampled(&MATERIAL)),
            Write::StorageImage(16, img(&rt_shadows::SHADOWS)),
            Write::StorageImage(17, img(&ao::AO)),
        ]);
        for (i, t) in rt_reflections::TARGETS.iter().enumerate() {
            writes.push(Write::StorageImage(18 + i as u32, img(t)));
        }
        writes.extend([
            Write::Buffer(22, &r.emitters),
            Write::Buffer(23, &r.triangle_emitter),
            Write::StorageImage(24, img(&rt_gi::GI)),
            Write::Buffer(25, &r.emissive),
        ]);
        for (i, t) in rt_direct::TARGETS.iter().enumerate() {
            writes.push(Write::StorageImage(26 + i as u32, img(t)));
        }
        writes.extend(scene.environment_writes(ENVIRONMENT_BINDING)?);
        // The probes where the file has them (`Needs::probes_if_present`), else zero constants
        // (the shaders test the dimensions) and placeholders that are never read.
        let (constants, atlases, states) = match &scene.probes {
            Some(p) => {
                let c = p.constants(probes::NORMAL_BIAS, probes::VIEW_BIAS);
                (c, [p.irradiance.view, p.visibility.view], &p.states)
            }
            None => (ProbeConstants::default(), [shared.dummies.array.view; 2], &r.emitters),
        };
        self.probe_constants.write(bytemuck::bytes_of(&constants))?;
        writes.extend([
            Write::Buffer(PROBE_BINDING, &self.probe_constants),
            Write::Sampled(PROBE_BINDING + 1, vec![(atlases[0], scene.linear_clamp)]),
            Write::Sampled(PROBE_BINDING + 2, vec![(atlases[1], scene.linear_clamp)]),
            Write::Buffer(PROBE_BINDING + 3, states),
        ]);
        if self.line_space {
            let ls = scene.line_space.as_ref().ok_or_else(|| {
                PlayError::new(Exit::Gpu, "a line-space pass is bound to a scene without its line space")
            })?;
            writes.extend(ls.writes(LINE_SPACE_BINDING));
        }
        self.layout.write(gpu, self.set, &writes);
        Ok(())
    }
}

/// The G-buffer reads of a ray-traced step plus `own` accesses.
pub fn io(own: &[(TargetDecl, Access)]) -> Vec<(TargetDecl, Access)> {
    let mut io = super::gbuffer::sampled(&GBUFFER_READS);
    io.extend_from_slice(own);
    io
}

/// One kernel over the shared table, dispatched over the whole frame: what the single-dispatch
/// ray-traced passes are. Released when dropped.
#[derive(Debug)]
pub struct HybridKernel {
    pipeline: ComputePipeline,
    set: HybridSet,
}

impl HybridKernel {
    /// The kernel from SPIR-V, decoding the texel buffer as `decode` says; on failure nothing
    /// is left behind.
    pub fn new(gpu: &Gpu, spirv: &[u8], decode: TexelDecode) -> PlayResult<HybridKernel> {
        Self::make(gpu, spirv, false, decode)
    }

    /// A kernel that also reads the line space.
    pub fn with_line_space(gpu: &Gpu, spirv: &[u8], decode: TexelDecode) -> PlayResult<HybridKernel> {
        Self::make(gpu, spirv, true, decode)
    }

    fn make(gpu: &Gpu, spirv: &[u8], line_space: bool, decode: TexelDecode) -> PlayResult<HybridKernel> {
        let set = HybridSet::new(gpu, line_space, decode)?;
        let pipeline = set.pipeline(gpu, spirv)?;
        Ok(HybridKernel { pipeline, set })
    }

    /// Allocates (once) and writes the set.
    pub fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.set.bind(gpu, shared)
    }

    /// Declares the G-buffer reads and `own` accesses, then dispatches over the frame.
    pub fn record(&self, ctx: &mut FrameCtx, own: &[(TargetDecl, Access)]) {
        ctx.images.access(ctx.rec, &io(own));
        let (w, h) = (ctx.images.width, ctx.images.height);
        ctx.rec.dispatch(
            &self.pipeline,
            &[self.set.set],
            bytemuck::bytes_of(ctx.rt),
            [w.div_ceil(8), h.div_ceil(8), 1],
        );
    }
}
