//! The peer of kiln's compute traversal: the driver's ray-tracing pipeline
//! (`VK_KHR_ray_tracing_pipeline`) over acceleration structures built at load from the baked
//! geometry (`VK_KHR_acceleration_structure`: one bottom-level structure of the file's triangles
//! in leaf order, so primitive indices equal kiln's triangle indices, and one instance). It traces
//! the same ray buffers into the same hit layout as [`crate::trace::RayQuery`], timed the same
//! way, so `--bench-rays` can compare the two on identical rays. Optional: absent when the device
//! lacks the extensions (lavapipe does). The Vulkan mechanics are in [`crate::gpu`]
//! ([`AccelerationStructures`], [`RayTracingPipeline`]).

use crate::error::PlayResult;
use crate::gpu::{
    AccelerationStructures, CommandPool, Gpu, RayTracingPipeline, RayTracingShaders, TimestampPool,
};
use crate::render::spirv;
use crate::trace::{GpuHit, GpuRay, timed_trace};

/// Push constants of `shaders/peer/trace.rgen`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Push {
    tlas: u64,
    rays: u64,
    hits: u64,
    count: u32,
    any_hit: u32,
}

/// Acceleration structures, pipeline and shader binding table, released when dropped (the GPU
/// must be done with them: each trace waits for itself, and the owner waits for the GPU).
pub struct RtPipelinePeer {
    /// Dropped first: waits for the last trace.
    pool: CommandPool,
    timestamps: TimestampPool,
    pipeline: RayTracingPipeline,
    structures: AccelerationStructures,
    /// GPU milliseconds of the acceleration-structure build.
    pub build_ms: f64,
    /// Untimed traces recorded before each timed one (see [`crate::trace::WARMUP_TRACES`]).
    pub warmup: u32,
}

impl std::fmt::Debug for RtPipelinePeer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RtPipelinePeer").field("build_ms", &self.build_ms).finish()
    }
}

impl RtPipelinePeer {
    /// Builds the structures over `corners` (three per triangle, leaf order) and the pipeline;
    /// `None` when the device has no ray-tracing pipeline enabled. On failure everything made is
    /// released.
    pub fn new(gpu: &Gpu, corners: &[[f32; 3]]) -> PlayResult<Option<RtPipelinePeer>> {
        if !gpu.ray_tracing_pipeline || corners.is_empty() {
            return Ok(None);
        }
        let pool = CommandPool::new(gpu, gpu.family)?;
        let timestamps = TimestampPool::new(gpu, 2)?;
        // On an error `make` has waited for the GPU before the pools are dropped.
        let (structures, pipeline, build_ms) = Self::make(gpu, corners, &pool, &timestamps)?;
        Ok(Some(RtPipelinePeer { pool, timestamps, pipeline, structures, build_ms, warmup: 0 }))
    }

    /// The structures (built, with the build's GPU milliseconds) and the pipeline; on failure
    /// the structures are released (dropped) once the GPU is idle.
    fn make(
        gpu: &Gpu,
        corners: &[[f32; 3]],
        pool: &CommandPool,
        timestamps: &TimestampPool,
    ) -> PlayResult<(AccelerationStructures, RayTracingPipeline, f64)> {
        let structures = AccelerationStructures::new(gpu, corners)?;
        let shaders = RayTracingShaders {
            raygen: spirv::shader!("peer/trace.rgen"),
            miss: spirv::shader!("peer/trace.rmiss"),
            closest_hit: spirv::shader!("peer/trace.rchit"),
        };
        let push_bytes = std::mem::size_of::<Push>() as u32;
        let made = Self::build(gpu, &structures, pool, timestamps)
            .and_then(|ms| RayTracingPipeline::new(gpu, &shaders, push_bytes).map(|p| (p, ms)));
        match made {
            Ok((pipeline, build_ms)) => Ok((structures, pipeline, build_ms)),
            Err(e) => {
                let _ = gpu.wait_idle();
                Err(e)
            }
        }
    }

    /// Builds the structures; returns the GPU milliseconds of the build.
    fn build(
        gpu: &Gpu,
        structures: &AccelerationStructures,
        pool: &CommandPool,
        timestamps: &TimestampPool,
    ) -> PlayResult<f64> {
        let rec = pool.begin(gpu)?;
        rec.reset_timestamps(timestamps);
        rec.timestamp(timestamps, 0);
        rec.build_structures(structures);
        rec.timestamp(timestamps, 1);
        pool.submit(gpu, &[], &[])?;
        pool.wait(gpu)?;
        let ns = timestamps.read_ns(gpu)?;
        Ok((ns[1] - ns[0]) * 1e-6)
    }

    /// Traces `rays` (closest hit, or any hit); returns one hit per ray and the GPU milliseconds
    /// of the trace alone.
    pub fn trace(&mut self, gpu: &Gpu, rays: &[GpuRay], any_hit: bool) -> PlayResult<(Vec<GpuHit>, f64)> {
        let this = &*self;
        timed_trace(
            gpu,
            &this.pool,
            &this.timestamps,
            rays,
            RayTracingPipeline::BUFFER_USAGE,
            this.warmup,
            |rec, input, output, count| {
                let push = Push {
                    tlas: this.structures.tlas_address(),
                    rays: input.address(gpu),
                    hits: output.address(gpu),
                    count,
                    any_hit: any_hit as u32,
                };
                rec.trace_rays(&this.pipeline, bytemuck::bytes_of(&push), count)
            },
        )
    }
}
