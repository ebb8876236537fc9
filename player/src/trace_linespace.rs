//! Ray queries through the resident line space (`shaders/trace/linespace.comp`): the same ray
//! buffers as [`crate::trace::RayQuery`], one query kind per trace, timed with timestamps. Tests
//! hold every kind to the CPU queries of `kiln-format`; `--bench-rays` reports their rays per
//! second next to the BVH's.

use gpu_allocator::MemoryLocation;

use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Buffer, Gpu, Write, vk};
use crate::render::spirv;
use crate::scene::BvhBuffers;
use crate::scene::linespace::LineSpaceBuffers;
use crate::trace::{GpuHit, GpuRay, TraceKernel, timed_trace};

/// Which query a trace runs (the shader's `mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LsQuery {
    /// Closest hit through the candidate lists (exact).
    CandidatesClosest = 0,
    /// Any hit through the candidate lists (exact).
    CandidatesAny = 1,
    /// Conservative any hit from the shaft bits alone.
    Binary = 2,
    /// The PNMT record hit (approximate); `t` and the material.
    Pnmt = 3,
    /// Shaft bits between the ray's ends, exact triangle tests in the cells holding them.
    BinaryEnds = 4,
    /// Exact triangle tests in every filled shaft's cell (exact any hit).
    BinaryFilled = 5,
}

impl LsQuery {
    /// Every query, in mode order.
    pub const ALL: [LsQuery; 6] = [
        LsQuery::CandidatesClosest,
        LsQuery::CandidatesAny,
        LsQuery::Binary,
        LsQuery::Pnmt,
        LsQuery::BinaryEnds,
        LsQuery::BinaryFilled,
    ];

    /// Short name (benchmark tables).
    pub fn name(self) -> &'static str {
        match self {
            LsQuery::CandidatesClosest => "candidates closest",
            LsQuery::CandidatesAny => "candidates any",
            LsQuery::Binary => "binary",
            LsQuery::Pnmt => "pnmt",
            LsQuery::BinaryEnds => "binary, exact near ends",
            LsQuery::BinaryFilled => "binary, exact filled",
        }
    }
}

/// The line-space queries, bound to one scene.
pub struct LineSpaceQuery {
    kernel: TraceKernel,
    /// Untimed traces recorded before each timed one (see [`crate::trace::WARMUP_TRACES`]).
    pub warmup: u32,
}

impl std::fmt::Debug for LineSpaceQuery {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LineSpaceQuery").finish()
    }
}

impl LineSpaceQuery {
    /// Builds the pipeline.
    pub fn new(gpu: &Gpu) -> PlayResult<LineSpaceQuery> {
        let mut bindings = vec![Binding::one(BindingKind::Storage); 5];
        bindings.extend(LineSpaceBuffers::bindings());
        Ok(LineSpaceQuery {
            kernel: TraceKernel::new(gpu, &bindings, spirv::shader!("trace/linespace.comp"))?,
            warmup: 0,
        })
    }

    /// Traces `rays` with `query`; `normals` (one per ray, or empty for none) are the geometric
    /// normals of the surfaces the rays leave, which PNMT's self-hit rule reads. Returns one
    /// hit per ray (any-hit queries: `t` 0 for a hit) and the GPU milliseconds of the trace.
    pub fn trace(
        &mut self,
        gpu: &Gpu,
        bvh: &BvhBuffers,
        line_space: &LineSpaceBuffers,
        rays: &[GpuRay],
        normals: &[[f32; 4]],
        query: LsQuery,
    ) -> PlayResult<(Vec<GpuHit>, f64)> {
        let words = rays.len().max(1) * 16;
        let mut normal_buffer = Buffer::new(
            gpu,
            "ray normals",
            words as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let mut bytes = vec![0u8; words];
        if normals.len() == rays.len() {
            bytes[..rays.len() * 16].copy_from_slice(bytemuck::cast_slice(normals));
        }
        normal_buffer.write(&bytes)?;
        // `normal_buffer` is dropped on return, when the trace has finished (or failed).
        let k = &self.kernel;
        let (layout, pipeline, set) = (&k.layout, &k.pipeline, k.set);
        let written = std::cell::Cell::new(false);
        let normal_buffer = &normal_buffer;
        timed_trace(
            gpu,
            &k.pool,
            &k.timestamps,
            rays,
            vk::BufferUsageFlags::empty(),
            self.warmup,
            |rec, input, output, count| {
                if !written.replace(true) {
                    let mut writes = vec![
                        Write::Buffer(0, &bvh.nodes),
                        Write::Buffer(1, &bvh.triangles),
                        Write::Buffer(2, input),
                        Write::Buffer(3, output),
                        Write::Buffer(4, normal_buffer),
                    ];
                    writes.extend(line_space.writes(5));
                    layout.write(gpu, set, &writes);
                }
                let push: [u32; 2] = [count, query as u32];
                rec.dispatch(pipeline, &[set], bytemuck::bytes_of(&push), [count.div_ceil(64), 1, 1]);
                vk::PipelineStageFlags2::COMPUTE_SHADER
            },
        )
    }
}
