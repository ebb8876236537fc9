//! `--reference`: the unbiased path tracer (`shaders/reference/pathtrace.comp`) run for a fixed
//! number of samples per pixel, accumulated on the GPU, written as linear radiance to EXR with
//! the sample count in the file's header (attribute `kilnSamplesPerPixel`).

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use crate::gpu::vk;
use gpu_allocator::MemoryLocation;
use kiln_format::gpu::{GpuLight, ReferenceConstants};

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Buffer, Use};
use crate::render::graph::{Access, FrameImages};
use crate::render::lights;
use crate::render::passes::pathtrace::{ACCUMULATION, PathTracePass};
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

/// Samples per pixel one dispatch takes at most. The shader starts a pixel's next sample as
/// soon as its path ends, so a dispatch of many samples keeps its invocations busy where one
/// of a single sample waits for its longest paths; 16 keeps a dispatch of 1600 × 900 on a
/// slow scene well under a second.
pub const SAMPLES_PER_DISPATCH: u32 = 16;

/// The random sequence `--reference` uses.
pub const DEFAULT_SEED: u32 = 0x2545_f491;

/// How a reference is sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sampling {
    /// Samples per pixel.
    pub spp: u32,
    /// The random sequence: images of different seeds are independent estimates (what a
    /// noise-floor estimate compares).
    pub seed: u32,
    /// Scattering events whose light counts: 0 no limit, 1 direct light alone.
    pub bounces: u32,
    /// Show the samples taken on stderr when it is a terminal (off under another progress bar).
    pub progress: bool,
}

impl Sampling {
    /// `spp` samples of the default sequence, every bounce, with progress.
    pub fn new(spp: u32) -> Sampling {
        Sampling { spp, seed: DEFAULT_SEED, bounces: 0, progress: true }
    }
}

/// Renders `spp` samples per pixel; returns the report and the mean radiance (RGB per pixel).
pub fn render(options: &SessionOptions, spp: u32, start: Instant) -> PlayResult<(ReferenceReport, Vec<f32>)> {
    render_with(options, Sampling::new(spp), start)
}

/// [`render`] sampled as `sampling` says.
pub fn render_with(
    options: &SessionOptions,
    sampling: Sampling,
    start: Instant,
) -> PlayResult<(ReferenceReport, Vec<f32>)> {
    let spp = sampling.spp;
    if spp == 0 {
        return Err(PlayError::new(Exit::Usage, "--spp must be at least 1"));
    }
    let mut options = options.clone();
    options.render.purpose = crate::render::Purpose::Reference;
    options.readback = None;
    // The path tracer renders no frame of the techniques: nothing to show before them.
    options.pipelines = crate::session::PipelineStart::Complete;
    // Nor any frame sampling coarse texture levels: every level before the first trace.
    options.textures = crate::scene::TextureUpload::Whole;
    let session = Session::open(&options, start)?;
    let result = sample(&session, sampling);
    let errors = session.close();
    let (report, pixels) = result?;
    if errors > 0 {
        return Err(PlayError::new(Exit::Gpu, format!("the validation layer reported {errors} error(s)")));
    }
    Ok((report, pixels))
}

fn sample(session: &Session, sampling: Sampling) -> PlayResult<(ReferenceReport, Vec<f32>)> {
    let Sampling { spp, seed, bounces, progress } = sampling;
    let gpu = &session.gpu;
    let scene = &session.scene;
    let Some(r) = &scene.reference else {
        return Err(PlayError::new(
            Exit::BadInput,
            "the file has no BVH (no triangles?): nothing to path trace",
        ));
    };
    let (w, h) = (session.renderer.images().width, session.renderer.images().height);
    let cam = &session.camera;
    let (right, up, half) = cam.image_axes();
    let sky = scene.manifest.sky.radiance;
    let environment_share = crate::scene::reference::environment_share(
        scene.environment.as_ref().map_or(0.0, |e| e.mean_luminance),
        crate::scene::reference::scene_radius(&scene.manifest),
        r.emitter_power,
    );
    let constants = ReferenceConstants {
        eye: [cam.position.x as f32, cam.position.y as f32, cam.position.z as f32, half as f32],
        right: [right.x as f32, right.y as f32, right.z as f32, w as f32 / h as f32],
        up: [up.x as f32, up.y as f32, up.z as f32, if cam.ortho.is_some() { 1.0 } else { 0.0 }],
        forward: [cam.forward.x as f32, cam.forward.y as f32, cam.forward.z as f32, 0.0],
        sky: [sky[0], sky[1], sky[2], environment_share],
        size: [w, h, spp, r.emitter_count],
        params: [scene.manifest.lights.len() as u32, MAX_PATH, seed, bounces],
        media: [r.media_count, 0, 0, 0],
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
        owned.images =
            Some(FrameImages::new(gpu, w, h, &[(ACCUMULATION, ACCUMULATION.sized(w, h, 1))], &[])?);
        owned.readback = Some(Buffer::new(
            gpu,
            "accumulation readback",
            w as u64 * h as u64 * 16,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?);
        owned.pass = Some(PathTracePass::new(gpu, r.texel_decode, r.media_count > 0)?);
        let (ubo, lights) = (owned.ubo.as_ref().expect("set"), owned.lights.as_ref().expect("set"));
        let images = owned.images.as_mut().expect("set");
        let pass = owned.pass.as_mut().expect("set");
        pass.bind(gpu, scene, ubo, lights, images)?;
        let pool = crate::gpu::CommandPool::new(gpu, gpu.family)?;
        owned.pool = Some(pool);
        let pool = owned.pool.as_ref().expect("set");
        let t0 = Instant::now();
        let progress = progress && std::io::stderr().is_terminal();
        let mut taken = 0u32;
        // A dispatch takes a few samples per pixel, more (up to SAMPLES_PER_DISPATCH) while
        // one stays short; a submission holds more dispatches while it takes under 25 ms: few
        // submissions, yet no long-running dispatch or command buffer that a watchdog could
        // take for a hang.
        let mut per_dispatch = 4u32.min(SAMPLES_PER_DISPATCH);
        let mut dispatches = 1u32;
        while taken < spp {
            let started = Instant::now();
            let rec = pool.begin(gpu)?;
            let mut recorded = 0;
            let mut recorded_dispatches = 0;
            while recorded_dispatches < dispatches && taken + recorded < spp {
                let count = per_dispatch.min(spp - taken - recorded);
                pass.record(&rec, images, taken + recorded, count);
                recorded += count;
                recorded_dispatches += 1;
            }
            pool.submit(gpu, &[], &[])?;
            pool.wait(gpu)?;
            taken += recorded;
            let ms = started.elapsed().as_secs_f64() * 1e3;
            let per = ms / recorded_dispatches as f64;
            if per < 50.0 && per_dispatch < SAMPLES_PER_DISPATCH {
                per_dispatch *= 2;
            } else if per > 200.0 && per_dispatch > 1 {
                per_dispatch /= 2;
            } else if ms < 25.0 {
                dispatches = (dispatches * 2).min(256);
            } else if ms > 100.0 && dispatches > 1 {
                dispatches /= 2;
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
        images.access(&rec, &[(ACCUMULATION, Access::Read(Use::TRANSFER_SRC))]);
        rec.copy_from_image(images.get(&ACCUMULATION), readback);
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
    // Whatever happened, the GPU is done with the resources before they are dropped.
    let _ = gpu.wait_idle();
    drop(owned);
    result
}

/// Resources of one reference render, dropped together whatever happened (once the GPU is
/// idle).
#[derive(Default)]
struct Owned {
    ubo: Option<Buffer>,
    lights: Option<Buffer>,
    images: Option<FrameImages>,
    readback: Option<Buffer>,
    pass: Option<PathTracePass>,
    pool: Option<crate::gpu::CommandPool>,
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
    let name = exr::meta::attribute::Text::from(SPP_ATTRIBUTE);
    // The exr crate files an attribute written as the image's under the layer's on reading.
    let value =
        header.shared_attributes.other.get(&name).or_else(|| header.own_attributes.other.get(&name))?;
    match value {
        exr::meta::attribute::AttributeValue::I32(n) => u32::try_from(*n).ok(),
        _ => None,
    }
}
