//! Ray queries on the GPU: a buffer of rays traced through the resident BVH by the compute
//! traversal (`shaders/common/traverse.glsl`), closest or any hit each, timed with timestamps.
//! Tests hold it to the CPU query of `kiln-format`; benchmarks report its rays per second.

use crate::gpu::vk;
use bytemuck::{Pod, Zeroable};
use gpu_allocator::MemoryLocation;

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{
    Binding, BindingKind, Buffer, CommandPool, ComputePipeline, Gpu, Recorder, SetLayout, TimestampPool,
    Write,
};
use crate::render::spirv;
use crate::scene::BvhBuffers;

/// A ray as the GPU reads it (32 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
#[repr(C)]
pub struct GpuRay {
    /// Origin.
    pub origin: [f32; 3],
    /// Start of the interval.
    pub tmin: f32,
    /// Direction (not necessarily unit).
    pub direction: [f32; 3],
    /// End of the interval.
    pub tmax: f32,
}

/// A hit as the GPU writes it (16 bytes); `t == NO_HIT` for a miss.
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
#[repr(C)]
pub struct GpuHit {
    /// Ray parameter, or [`NO_HIT`].
    pub t: f32,
    /// Triangle in leaf order.
    pub triangle: u32,
    /// Barycentric weight of corner 1.
    pub u: f32,
    /// Barycentric weight of corner 2.
    pub v: f32,
}

/// `t` of a miss (`NO_HIT` in the shader).
pub const NO_HIT: f32 = 3.402823e38;

/// A compute kernel that traces a buffer of rays: its pipeline over one set (rewritten by every
/// trace: the previous trace has finished by then), its command pool and timestamps. What the
/// BVH's and the line space's queries share. Dropping it waits for its last trace (the pool
/// goes first), then releases everything.
pub(crate) struct TraceKernel {
    pub(crate) pool: CommandPool,
    pub(crate) timestamps: TimestampPool,
    pub(crate) pipeline: ComputePipeline,
    pub(crate) layout: SetLayout,
    pub(crate) set: vk::DescriptorSet,
}

impl TraceKernel {
    /// The kernel of `spirv` over `bindings`, with 8 bytes of push constants (count, mode); on
    /// failure nothing is left behind.
    pub(crate) fn new(gpu: &Gpu, bindings: &[Binding], spirv: &[u8]) -> PlayResult<TraceKernel> {
        let layout = SetLayout::new(gpu, bindings, 1)?;
        let pipeline = ComputePipeline::new(gpu, spirv, &[&layout], 8)?;
        let mut kernel = TraceKernel {
            set: vk::DescriptorSet::null(),
            pool: CommandPool::new(gpu, gpu.family)?,
            timestamps: TimestampPool::new(gpu, 2)?,
            layout,
            pipeline,
        };
        kernel.set = kernel.layout.allocate(gpu)?;
        Ok(kernel)
    }
}

/// The compute traversal, bound to one scene's BVH (released when dropped, after its scene's
/// session has waited for it: each trace waits for itself).
pub struct RayQuery {
    kernel: TraceKernel,
    /// Untimed traces recorded before each timed one (0; benchmarks set [`WARMUP_TRACES`]).
    pub warmup: u32,
}

impl std::fmt::Debug for RayQuery {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RayQuery").finish()
    }
}

impl RayQuery {
    /// Builds the pipeline.
    pub fn new(gpu: &Gpu) -> PlayResult<RayQuery> {
        let storage = Binding::one(BindingKind::Storage);
        Ok(RayQuery {
            kernel: TraceKernel::new(gpu, &[storage; 4], spirv::shader!("trace/rays.comp"))?,
            warmup: 0,
        })
    }

    /// Traces `rays` through `bvh`; returns one hit per ray and the GPU milliseconds of the
    /// traversal alone.
    pub fn trace(
        &mut self,
        gpu: &Gpu,
        bvh: &BvhBuffers,
        rays: &[GpuRay],
        any_hit: bool,
    ) -> PlayResult<(Vec<GpuHit>, f64)> {
        let k = &self.kernel;
        let (layout, pipeline, set) = (&k.layout, &k.pipeline, k.set);
        let usage = vk::BufferUsageFlags::empty();
        // The set points at this trace's buffers; it is written once, before its first use (the
        // trace is recorded several times, and writing a bound set invalidates the recording).
        let written = std::cell::Cell::new(false);
        timed_trace(gpu, &k.pool, &k.timestamps, rays, usage, self.warmup, |rec, input, output, count| {
            if !written.replace(true) {
                layout.write(
                    gpu,
                    set,
                    &[
                        Write::Buffer(0, &bvh.nodes),
                        Write::Buffer(1, &bvh.triangles),
                        Write::Buffer(2, input),
                        Write::Buffer(3, output),
                    ],
                );
            }
            let push: [u32; 2] = [count, any_hit as u32];
            rec.dispatch(pipeline, &[set], bytemuck::bytes_of(&push), [count.div_ceil(64), 1, 1]);
            vk::PipelineStageFlags2::COMPUTE_SHADER
        })
    }
}

/// Untimed traces a benchmark records before each timed one (see [`timed_trace`]).
pub const WARMUP_TRACES: u32 = 3;

/// Runs one timed trace of `rays`: fills a host-visible ray buffer, records `record` (given the
/// ray and hit buffers, created with storage plus `usage`, and the ray count; it returns the
/// stage that writes the hits) between two timestamps, waits, and returns the hits and the GPU
/// milliseconds between the timestamps. Shared by the compute traversal and its peer.
///
/// Benchmarks record the same trace `warmup` times before the timed one, in the same
/// submission: a lone sub-millisecond dispatch after the host's work on the buffers ran at
/// whatever clock the idle GPU had dropped to (on an H200, 2–7× slower on later ray sets).
pub(crate) fn timed_trace(
    gpu: &Gpu,
    pool: &CommandPool,
    timestamps: &TimestampPool,
    rays: &[GpuRay],
    usage: vk::BufferUsageFlags,
    warmup: u32,
    record: impl Fn(&Recorder, &Buffer, &Buffer, u32) -> vk::PipelineStageFlags2,
) -> PlayResult<(Vec<GpuHit>, f64)> {
    if rays.is_empty() {
        return Ok((Vec::new(), 0.0));
    }
    let count =
        u32::try_from(rays.len()).map_err(|_| PlayError::new(Exit::Usage, "too many rays in one batch"))?;
    let bytes: &[u8] = bytemuck::cast_slice(rays);
    let usage = usage | vk::BufferUsageFlags::STORAGE_BUFFER;
    let mut input = Buffer::new(gpu, "rays", bytes.len() as u64, usage, MemoryLocation::CpuToGpu)?;
    let out_size = rays.len() * 16;
    let mut output = Buffer::new(gpu, "hits", out_size as u64, usage, MemoryLocation::GpuToCpu)?;
    input.write(bytes)?;
    // The buffers are dropped on return, when the trace has finished (`pool.wait`) or failed.
    let rec = pool.begin(gpu)?;
    rec.reset_timestamps(timestamps);
    for _ in 0..warmup {
        let stage = record(&rec, &input, &output, count);
        // The next trace overwrites the same hits.
        rec.memory_barrier(
            stage,
            vk::AccessFlags2::SHADER_STORAGE_WRITE,
            stage,
            vk::AccessFlags2::SHADER_STORAGE_WRITE,
        );
    }
    rec.timestamp(timestamps, 0);
    let stage = record(&rec, &input, &output, count);
    rec.timestamp(timestamps, 1);
    rec.memory_barrier(
        stage,
        vk::AccessFlags2::SHADER_STORAGE_WRITE,
        vk::PipelineStageFlags2::HOST,
        vk::AccessFlags2::HOST_READ,
    );
    pool.submit(gpu, &[], &[])?;
    pool.wait(gpu)?;
    let ns = timestamps.read_ns(gpu)?;
    let hits: Vec<GpuHit> = output
        .mapped()
        .map(|m| bytemuck::pod_collect_to_vec(&m[..out_size]))
        .ok_or_else(|| PlayError::new(Exit::Gpu, "the hit buffer is not host-visible"))?;
    Ok((hits, (ns[1] - ns[0]) * 1e-6))
}
