//! A compute kernel with its own set layout and descriptor sets (one for most passes; several
//! where one pipeline runs over different images in turn, e.g. a chain of blurs).

use crate::error::PlayResult;
use crate::gpu::{Binding, ComputePipeline, Gpu, Recorder, SetLayout, Write, vk};
use crate::render::TexelDecode;

/// Layout, pipeline and sets of one compute kernel, released when dropped.
#[derive(Debug)]
pub struct Kernel {
    pipeline: ComputePipeline,
    layout: SetLayout,
    sets: Vec<vk::DescriptorSet>,
}

impl Kernel {
    /// A kernel from SPIR-V over a set of `bindings`, with `push_bytes` of push constants. On
    /// failure nothing is left behind.
    pub fn new(gpu: &Gpu, bindings: &[Binding], spirv: &[u8], push_bytes: u32) -> PlayResult<Kernel> {
        Self::specialized(gpu, bindings, spirv, push_bytes, &[])
    }

    /// `N` kernels, one per (bindings, SPIR-V), all with `push_bytes` of push constants: the
    /// pipelines of a pass made of several steps. On failure those already made are released.
    pub fn several<const N: usize>(
        gpu: &Gpu,
        specs: [(&[Binding], &[u8]); N],
        push_bytes: u32,
    ) -> PlayResult<[Kernel; N]> {
        let made = specs
            .into_iter()
            .map(|(bindings, spirv)| Kernel::new(gpu, bindings, spirv, push_bytes))
            .collect::<PlayResult<Vec<Kernel>>>()?;
        Ok(made.try_into().unwrap_or_else(|_| unreachable!("one kernel per spec")))
    }

    /// [`Kernel::new`] for a kernel that reads the texel buffer, specialized for `decode`.
    pub fn reading_texels(
        gpu: &Gpu,
        bindings: &[Binding],
        spirv: &[u8],
        push_bytes: u32,
        decode: TexelDecode,
    ) -> PlayResult<Kernel> {
        Self::specialized(gpu, bindings, spirv, push_bytes, &decode.constants())
    }

    /// [`Kernel::new`] with specialization constants: `constants[i]` for constant id `i`.
    pub fn specialized(
        gpu: &Gpu,
        bindings: &[Binding],
        spirv: &[u8],
        push_bytes: u32,
        constants: &[u32],
    ) -> PlayResult<Kernel> {
        let layout = SetLayout::new(gpu, bindings, 1)?;
        let pipeline = ComputePipeline::specialized(gpu, spirv, &[&layout], push_bytes, constants)?;
        Ok(Kernel { pipeline, layout, sets: Vec::new() })
    }

    /// Writes set 0 (allocated by the first call).
    pub fn write(&mut self, gpu: &Gpu, writes: &[Write]) -> PlayResult {
        self.write_set(gpu, 0, writes)
    }

    /// Writes set `index` (allocating the sets up to it by the first call).
    pub fn write_set(&mut self, gpu: &Gpu, index: usize, writes: &[Write]) -> PlayResult {
        while self.sets.len() <= index {
            self.sets.push(self.layout.allocate(gpu)?);
        }
        self.layout.write(gpu, self.sets[index], writes);
        Ok(())
    }

    /// Dispatches 8 × 8 groups over `width` × `height` with `push` constants and set 0.
    pub fn dispatch(&self, rec: &Recorder, push: &[u8], width: u32, height: u32) {
        self.dispatch_set(rec, 0, push, width, height);
    }

    /// [`Kernel::dispatch`] with set `index` (written before).
    pub fn dispatch_set(&self, rec: &Recorder, index: usize, push: &[u8], width: u32, height: u32) {
        rec.dispatch(&self.pipeline, &[self.sets[index]], push, [width.div_ceil(8), height.div_ceil(8), 1]);
    }
}
