//! `--reference`: the unbiased path tracer (`shaders/reference/pathtrace.comp`) run for a fixed
//! number of samples per pixel, accumulated on the GPU, written as linear radiance to EXR with
//! the sample count in the file's header (attribute `kilnSamplesPerPixel`).

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use ash::vk;
use gpu_allocator::MemoryLocation;
use kiln_format::gpu::{GpuLight, ReferenceConstants};

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Binding, BindingKind, Buffer, ComputePipeline, Image, ImageDesc, SetLayout, Use, Write};
use crate::render::{lights, spirv};
use crate::session::{Session, SessionOptions};

/// What a reference render measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ReferenceReport {
    /// Device name.
    pub device: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel taken.
    pub spp: u32,
    /// Wall-clock seconds of the sampling (load excluded).
    pub seconds: f64,
    /// Pixel samples (full paths) per second.
    pub samples_per_second: f64,
}

/// The EXR header attribute holding the sample count.
pub const SPP_ATTRIBUTE: &str = "kilnSamplesPerPixel";

/// Default cap on path length (vertices); Russian roulette ends nearly every path long before.
pub const MAX_PATH: u32 = 1024;

/// Renders `spp` samples per pixel; returns the report and the mean radiance (RGB per pixel).
pub fn render(options: &SessionOptions, spp: u32, start: Instant) -> PlayResult<(ReferenceReport, Vec<f32>)> {
    if spp == 0 {
        return Err(PlayError::new(Exit::Usage, "--spp must be at least 1"));
    }
    let mut options = options.clone();
    options.render.purpose = crate::render::Purpose::Reference;
    options.readback = None;
    let session = Session::open(&options, start)?;
    let result = sample(&session, spp);
    let errors = session.close();
    let (report, pixels) = result?;
    if errors > 0 {
        return Err(PlayError::new(Exit::Gpu, format!("the validation layer reported {errors} error(s)")));
    }
    Ok((report, pixels))
}

fn sample(session: &Session, spp: u32) -> PlayResult<(ReferenceReport, Vec<f32>)> {
    let gpu = &session.gpu;
    let scene = &session.scene;
    let (Some(common), Some(r)) = (scene.ray_writes(), &scene.reference) else {
        return Err(PlayError::new(
            Exit::BadInput,
            "the file has no BVH (no triangles?): nothing to path trace",
        ));
    };
    let (w, h) = (session.renderer.images().width, session.renderer.images().height);
    let cam = &session.camera;
    let right = cam.forward.cross(cam.up).normalize_or(glam::DVec3::X);
    let up = right.cross(cam.forward);
    let sky = scene.manifest.sky.radiance;
    let constants = ReferenceConstants {
        eye: [
            cam.position.x as f32,
            cam.position.y as f32,
            cam.position.z as f32,
            (cam.vfov_degrees.to_radians() * 0.5).tan() as f32,
        ],
        right: [right.x as f32, right.y as f32, right.z as f32, w as f32 / h as f32],
        up: [up.x as f32, up.y as f32, up.z as f32, 0.0],
        forward: [cam.forward.x as f32, cam.forward.y as f32, cam.forward.z as f32, 0.0],
        sky: [sky[0], sky[1], sky[2], 0.0],
        size: [w, h, spp, r.emitter_count],
        params: [scene.manifest.lights.len() as u32, MAX_PATH, 0x2545_f491, 0],
    };
    let plan: Vec<GpuLight> = lights::plan(&scene.manifest, &[], false).lights;
    let mut owned = Owned::default();
    let result = (|| -> PlayResult<(ReferenceReport, Vec<f32>)> {
        let host = |name: &str, bytes: &[u8], usage| -> PlayResult<Buffer> {
            let mut b = Buffer::new(gpu, name, bytes.len() as u64, usage, MemoryLocation::CpuToGpu)?;
            b.write(bytes)?;
            Ok(b)
        };
        owned.ubo = Some(host(
            "reference constants",
            bytemuck::bytes_of(&constants),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?);
        owned.lights = Some(host(
            "reference lights",
            bytemuck::cast_slice(&plan),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?);
        let usage = vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::TRANSFER_SRC;
        let desc = ImageDesc {
            format: vk::Format::R32G32B32A32_SFLOAT,
            width: w,
            height: h,
            mips: 1,
            layers: 1,
            cube: false,
            array: false,
            usage,
            uploaded: false,
        };
        owned.image = Some(Image::new(gpu, "accumulation", desc)?);
        owned.readback = Some(Buffer::new(
            gpu,
            "accumulation readback",
            w as u64 * h as u64 * 16,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?);
        let storage = Binding { kind: BindingKind::Storage, count: 1 };
        let mut bindings = vec![Binding { kind: BindingKind::Uniform, count: 1 }];
        bindings.extend([storage; 12]);
        bindings.push(Binding { kind: BindingKind::StorageImage, count: 1 });
        owned.layout = Some(SetLayout::new(gpu, &bindings, 1)?);
        let layout = owned.layout.as_mut().expect("just set");
        owned.pipeline = Some(ComputePipeline::new(gpu, spirv::PATHTRACE, &[layout], 4)?);
        let set = layout.allocate(gpu)?;
        let (ubo, lights, image) = (
            owned.ubo.as_ref().expect("set"),
            owned.lights.as_ref().expect("set"),
            owned.image.as_ref().expect("set"),
        );
        let mut writes = vec![Write::Buffer(0, ubo)];
        writes.extend(common);
        writes.extend([
            Write::Buffer(crate::scene::bindings::LIGHTS.binding, lights),
            Write::Buffer(9, &r.emitters),
            Write::Buffer(10, &r.triangle_emitter),
            Write::Buffer(11, &r.texels),
            Write::Buffer(12, &r.textures),
            Write::StorageImage(13, image.view),
        ]);
        layout.write(gpu, set, &writes);
        let pipeline = owned.pipeline.as_ref().expect("set");
        let pool = crate::gpu::CommandPool::new(gpu, gpu.family)?;
        owned.pool = Some(pool);
        let pool = owned.pool.as_ref().expect("set");
        let t0 = Instant::now();
        let progress = std::io::stderr().is_terminal();
        let mut taken = 0u32;
        // Batches grow until one takes about 50 ms: few submissions, yet no long-running
        // command buffer that a watchdog could take for a hang.
        let mut batch = 1u32;
        let mut first = true;
        while taken < spp {
            let n = batch.min(spp - taken);
            let started = Instant::now();
            let rec = pool.begin(gpu)?;
            for i in 0..n {
                if first {
                    rec.transition(image, Use::DISCARD, Use::STORAGE);
                    first = false;
                } else {
                    rec.transition(image, Use::STORAGE, Use::STORAGE);
                }
                let index = taken + i;
                rec.dispatch(pipeline, &[set], bytemuck::bytes_of(&index), [w.div_ceil(8), h.div_ceil(8), 1]);
            }
            pool.submit(gpu, &[], &[])?;
            pool.wait(gpu)?;
            taken += n;
            let ms = started.elapsed().as_secs_f64() * 1e3;
            if ms < 25.0 {
                batch = (batch * 2).min(256);
            } else if ms > 100.0 && batch > 1 {
                batch /= 2;
            }
            if progress {
                eprint!("\r{taken}/{spp} samples per pixel ({:.1} s)", t0.elapsed().as_secs_f64());
            }
        }
        if progress {
            eprintln!();
        }
        let seconds = t0.elapsed().as_secs_f64();
        let readback = owned.readback.as_mut().expect("set");
        let rec = pool.begin(gpu)?;
        rec.transition(image, Use::STORAGE, Use::TRANSFER_SRC);
        rec.copy_from_image(image, readback);
        rec.memory_barrier(
            vk::PipelineStageFlags2::TRANSFER,
            vk::AccessFlags2::TRANSFER_WRITE,
            vk::PipelineStageFlags2::HOST,
            vk::AccessFlags2::HOST_READ,
        );
        pool.submit(gpu, &[], &[])?;
        pool.wait(gpu)?;
        let bytes = readback
            .mapped()
            .ok_or_else(|| PlayError::new(Exit::Gpu, "the readback buffer is not host-visible"))?;
        let sums: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes[..w as usize * h as usize * 16]);
        let scale = 1.0 / spp as f32;
        let mean: Vec<f32> =
            sums.chunks_exact(4).flat_map(|p| [p[0] * scale, p[1] * scale, p[2] * scale]).collect();
        let samples = w as f64 * h as f64 * spp as f64;
        Ok((
            ReferenceReport {
                device: gpu.name.clone(),
                width: w,
                height: h,
                spp,
                seconds,
                samples_per_second: samples / seconds.max(1e-9),
            },
            mean,
        ))
    })();
    owned.destroy(session);
    result
}

/// Resources of one reference render, released together whatever happened.
#[derive(Default)]
struct Owned {
    ubo: Option<Buffer>,
    lights: Option<Buffer>,
    image: Option<Image>,
    readback: Option<Buffer>,
    layout: Option<SetLayout>,
    pipeline: Option<ComputePipeline>,
    pool: Option<crate::gpu::CommandPool>,
}

impl Owned {
    fn destroy(&mut self, session: &Session) {
        let gpu = &session.gpu;
        let _ = gpu.wait_idle();
        if let Some(p) = &mut self.pool {
            p.destroy(gpu);
        }
        if let Some(p) = &mut self.pipeline {
            p.destroy(gpu);
        }
        if let Some(l) = &mut self.layout {
            l.destroy(gpu);
        }
        for b in [&mut self.ubo, &mut self.lights, &mut self.readback].into_iter().flatten() {
            b.destroy(gpu);
        }
        if let Some(i) = &mut self.image {
            i.destroy(gpu);
        }
    }
}

/// Writes linear RGB radiance as float EXR with the sample count in the header.
pub fn write_exr(path: &Path, width: u32, height: u32, rgb: &[f32], spp: u32) -> PlayResult {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|Vec2(x, y)| {
        let i = (y * width as usize + x) * 3;
        (rgb[i], rgb[i + 1], rgb[i + 2])
    });
    let mut image = Image::from_channels((width as usize, height as usize), channels);
    image
        .attributes
        .other
        .insert(Text::from(SPP_ATTRIBUTE), AttributeValue::I32(spp.min(i32::MAX as u32) as i32));
    let mut bytes = std::io::Cursor::new(Vec::new());
    image
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| PlayError::new(Exit::Io, format!("encoding EXR: {e}")))?;
    crate::image_out::write_atomic(path, &bytes.into_inner())
}

/// The sample count recorded in an EXR written by [`write_exr`].
pub fn read_spp(path: &Path) -> Option<u32> {
    let meta = exr::meta::MetaData::read_from_file(path, false).ok()?;
    let header = meta.headers.first()?;
    match header.shared_attributes.other.get(&exr::meta::attribute::Text::from(SPP_ATTRIBUTE))? {
        exr::meta::attribute::AttributeValue::I32(n) => u32::try_from(*n).ok(),
        _ => None,
    }
}
