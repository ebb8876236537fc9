//! A compute kernel with its own set layout and one descriptor set: what most passes are.

use crate::error::PlayResult;
use crate::gpu::{Binding, ComputePipeline, Gpu, Recorder, SetLayout, Write, vk};
use crate::render::TexelDecode;

/// Layout, pipeline and set of one compute kernel.
#[derive(Debug)]
pub struct Kernel {
    layout: SetLayout,
    pipeline: ComputePipeline,
    set: vk::DescriptorSet,
}

impl Kernel {
    /// A kernel from SPIR-V over a set of `bindings`, with `push_bytes` of push constants. On
    /// failure nothing is left behind.
    pub fn new(gpu: &Gpu, bindings: &[Binding], spirv: &[u8], push_bytes: u32) -> PlayResult<Kernel> {
        Self::make(gpu, bindings, spirv, push_bytes, &[])
    }

    /// [`Kernel::new`] for a kernel that reads the texel buffer, specialized for `decode`.
    pub fn reading_texels(
        gpu: &Gpu,
        bindings: &[Binding],
        spirv: &[u8],
        push_bytes: u32,
        decode: TexelDecode,
    ) -> PlayResult<Kernel> {
        Self::make(gpu, bindings, spirv, push_bytes, &decode.constants())
    }

    fn make(
        gpu: &Gpu,
        bindings: &[Binding],
        spirv: &[u8],
        push_bytes: u32,
        constants: &[u32],
    ) -> PlayResult<Kernel> {
        let mut layout = SetLayout::new(gpu, bindings, 1)?;
        match ComputePipeline::specialized(gpu, spirv, &[&layout], push_bytes, constants) {
            Ok(pipeline) => Ok(Kernel { layout, pipeline, set: vk::DescriptorSet::null() }),
            Err(e) => {
                layout.destroy(gpu);
                Err(e)
            }
        }
    }

    /// Writes the set (allocated by the first call).
    pub fn write(&mut self, gpu: &Gpu, writes: &[Write]) -> PlayResult {
        if self.set == vk::DescriptorSet::null() {
            self.set = self.layout.allocate(gpu)?;
        }
        self.layout.write(gpu, self.set, writes);
        Ok(())
    }

    /// Dispatches 8 × 8 groups over `width` × `height` with `push` constants.
    pub fn dispatch(&self, rec: &Recorder, push: &[u8], width: u32, height: u32) {
        rec.dispatch(&self.pipeline, &[self.set], push, [width.div_ceil(8), height.div_ceil(8), 1]);
    }

    /// Releases pipeline and layout (and the set with it).
    pub fn destroy(&mut self, gpu: &Gpu) {
        self.pipeline.destroy(gpu);
        self.layout.destroy(gpu);
    }
}
