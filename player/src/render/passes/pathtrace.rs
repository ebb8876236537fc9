//! The reference path tracer's pass (`shaders/reference/pathtrace.comp`): unbiased samples per
//! pixel, several per dispatch, summed into an accumulation target. [`crate::reference`] drives it
//! for a fixed sample count and writes the mean.

use crate::gpu::vk;

use super::kernel::Kernel;
use crate::render::TexelDecode;

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Binding, BindingKind, Buffer, Gpu, Use, Write};
use crate::render::graph::{Access, FrameImages, TargetDecl};
use crate::render::spirv;
use crate::scene::GpuScene;
use crate::scene::bindings;

/// The sum of the samples so far (rgb; a counts them).
pub const ACCUMULATION: TargetDecl = TargetDecl {
    name: "accumulation",
    format: vk::Format::R32G32B32A32_SFLOAT,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::STORAGE.as_raw() | vk::ImageUsageFlags::TRANSFER_SRC.as_raw(),
    ),
    array: false,
};

/// Samples of a pixel taken side by side (`STREAMS` in the shader, at most its `MAX_STREAMS`).
/// Measured on an H200, 1,024 spp, 1, 2 and 4 (the images the same to the bit): at 640 × 360
/// ToyCar 85.0 / 95.4 / 101.2 M samples/s, LightsPunctualLamp 496 / 647 / 819, pica_pica 156 /
/// 190 / 209; at 1600 × 900 104 / 107 / 114, 959 / 1,058 / 1,177 and 234 / 224 / 224
/// (docs/benchmarks/reference-speed/h200-streams.txt).
const STREAMS: u32 = 4;

/// The path tracer's pipeline and set.
#[derive(Debug)]
pub struct PathTracePass(Kernel);

impl PathTracePass {
    /// Builds the pipeline for a texel buffer that `decode` reads, with the participating
    /// media's code only where the file has `media`.
    pub fn new(gpu: &Gpu, decode: TexelDecode, media: bool) -> PlayResult<PathTracePass> {
        use BindingKind::*;
        let mut bindings = vec![Binding::one(Uniform)];
        bindings.extend([Binding::one(Storage); 12]);
        bindings.push(Binding::one(StorageImage));
        bindings.push(Binding::one(Storage));
        bindings.extend([Binding::one(Storage); 2]);
        let [texels_bc] = decode.constants();
        Ok(PathTracePass(Kernel::specialized(
            gpu,
            &bindings,
            spirv::shader!("reference/pathtrace.comp"),
            std::mem::size_of::<[u32; 2]>() as u32,
            &[texels_bc, media as u32, STREAMS],
        )?))
    }

    /// Allocates and writes the set: `constants` holds `ReferenceConstants`, `lights` the
    /// lights, `images` the accumulation target.
    pub fn bind(
        &mut self,
        gpu: &Gpu,
        scene: &GpuScene,
        constants: &Buffer,
        lights: &Buffer,
        images: &FrameImages,
    ) -> PlayResult {
        let (Some(common), Some(r)) = (scene.ray_writes(), &scene.reference) else {
            return Err(PlayError::new(
                Exit::BadInput,
                "the file has no BVH (no triangles?): nothing to path trace",
            ));
        };
        let mut writes = vec![Write::Buffer(0, constants)];
        writes.extend(common);
        writes.extend([
            Write::Buffer(bindings::LIGHTS.binding, lights),
            Write::Buffer(9, &r.emitters),
            Write::Buffer(10, &r.triangle_emitter),
            Write::Buffer(11, &r.texels),
            Write::Buffer(12, &r.textures),
            Write::StorageImage(13, images.get(&ACCUMULATION).view),
            Write::Buffer(14, &r.media),
        ]);
        writes.extend(scene.environment_writes(15)?);
        self.0.write(gpu, &writes)
    }

    /// Records samples `first .. first + count` (first 0 overwrites the accumulation, later
    /// ones add to it).
    pub fn record(&self, rec: &crate::gpu::Recorder, images: &mut FrameImages, first: u32, count: u32) {
        images.access(rec, &[(ACCUMULATION, Access::ReadWrite(Use::STORAGE))]);
        self.0.dispatch(rec, bytemuck::bytes_of(&[first, count]), images.width, images.height);
    }
}
