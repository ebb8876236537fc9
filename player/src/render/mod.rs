//! The frame: one file per pass under [`passes`], one module per technique under
//! [`techniques`], the
//! passes of a run wired by [`frame`] with barriers derived from their declared reads and writes
//! ([`graph`]). Pipelines are built without the scene (so they compile while it uploads);
//! [`Renderer::new`] then binds the scene.
//!
//! The ray-traced passes take one sample per pixel per frame and average frames while the
//! camera is still (a running mean, `--aa accumulate`); any change of the view or
//! projection restarts the average (no reprojection: a moving camera sees the one-sample image).

pub mod background;
pub mod dummies;
pub mod frame;
pub mod graph;
pub mod lights;
pub mod passes;
pub mod presets;
pub mod spirv;
pub mod techniques;
pub mod texels;

use crate::gpu::vk;
use gpu_allocator::MemoryLocation;
use kiln_format::gpu::{FrameConstants, FrameFlags, LightKinds, RtConstants};

use crate::camera::Camera;
use crate::error::PlayResult;
use crate::gpu::{Buffer, Gpu, Image, Recorder, TimestampPool, Use};
use crate::scene::GpuScene;
pub use dummies::Dummies;
use frame::Frame;
use graph::{Access, FrameImages};
use passes::{FrameCtx, Shared};
pub use techniques::{
    Aa, Ao, Effect, GBuffer, Gi, Media, Needs, Reflections, ScreenFraction, Shadows, Techniques,
};
pub use texels::TexelDecode;

/// Shadow maps of each kind the direct-light pass can bind, and lights with a ray-traced shadow
/// layer: defined once in `kiln_format::gpu`, which also emits them into the shaders' `layout.glsl`.
pub use kiln_format::gpu::{MAX_RT_SHADOW_LIGHTS, MAX_SHADOW_MAPS};

/// What a session is opened for, beyond frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Purpose {
    /// Frames of the chosen techniques.
    #[default]
    Frames,
    /// Frames, and ray queries through the BVH ([`crate::trace::RayQuery`]) and whatever line
    /// space the file has ([`crate::trace_linespace::LineSpaceQuery`]).
    RayQueries,
    /// The reference path tracer.
    Reference,
}

/// How to render.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RenderSettings {
    /// One technique per effect.
    pub techniques: Techniques,
    /// Exposure in stops (the radiance is multiplied by 2^exposure before tone mapping).
    pub exposure: f32,
    /// What else the session serves.
    pub purpose: Purpose,
}

impl RenderSettings {
    /// The sections of the file the run reads: the union of the techniques' needs and the
    /// purpose's, decided here once.
    pub fn needs(&self) -> Needs {
        let n = self.techniques.needs();
        match self.purpose {
            Purpose::Frames => n,
            // Whatever line space the file has: the ray benchmark measures every variant.
            Purpose::RayQueries => n.union(Needs {
                line_space: crate::scene::linespace::LsArrays::ALL
                    | crate::scene::linespace::LsArrays::IF_PRESENT,
                ..Needs::RAYS
            }),
            // The path tracer decodes no BC block: its texel buffer holds RGBA8 (ToyCar 59–62 →
            // 66–70 M samples/s on an H200, docs/benchmarks/reference-speed/).
            Purpose::Reference => n.union(Needs { decoded_texels: true, ..Needs::TRACED_SURFACES }),
        }
    }
}

/// GPU milliseconds of each pass of a frame, by pass name, in frame order.
pub type PassTimes = Vec<(&'static str, f64)>;

/// Renders a resident scene. Dropping it releases everything it owns: the GPU must be done with
/// it (its owner waits for the GPU first).
pub struct Renderer {
    frame: Frame,
    frame_ubo: Buffer,
    lights: Buffer,
    shadows: Buffer,
    plan: lights::LightPlan,
    rt_constants: RtConstants,
    /// Frames averaged at the current camera.
    accumulated: u32,
    /// The previous frame's world to clip without jitter; `None` before the first frame and
    /// after a resize (the history images then hold nothing).
    last_view_proj: Option<glam::DMat4>,
    /// This frame's world to clip without jitter (the see-through layer's screen area).
    view_proj: glam::DMat4,
    /// Whether this frame has a previous one to read (the constants say so to the shaders; a
    /// frame without records [`Frame::again`]).
    history: bool,
    flags: u32,
    lut_resolution: u32,
    sky: [f32; 3],
    /// Media that dim the light reaching surfaces (those of the scene when a media technique
    /// runs; 0 otherwise).
    media_dimming: u32,
    settings: RenderSettings,
    timestamps: TimestampPool,
    /// Frames rendered.
    pub frame_count: u64,
    /// Notes for the user (e.g. lights left unshadowed).
    pub warnings: Vec<String>,
}

impl std::fmt::Debug for Renderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Renderer")
            .field("size", &(self.frame.images.width, self.frame.images.height))
            .finish()
    }
}

fn host_buffer(gpu: &Gpu, name: &str, bytes: &[u8], usage: vk::BufferUsageFlags) -> PlayResult<Buffer> {
    let mut buf = Buffer::new(gpu, name, bytes.len() as u64, usage, MemoryLocation::CpuToGpu)?;
    buf.write(bytes)?;
    Ok(buf)
}

impl Renderer {
    /// Binds `scene` to the passes of `frame`, with `dummies` where nothing else is bound (the
    /// session's: they must outlive the renderer). On failure the frame is released (dropped;
    /// the GPU has not used it).
    pub fn new(
        gpu: &Gpu,
        frame: Frame,
        dummies: &Dummies,
        scene: &GpuScene,
        settings: RenderSettings,
    ) -> PlayResult<Renderer> {
        let t = settings.techniques;
        // The shadow maps are bound for whatever reads them (`--shadows shadowmap`, the media
        // march through them, `--media toth`); the flag below says whether surfaces use them.
        let surface_maps = t.shadow_mapped_surfaces();
        let mut plan = lights::plan(&scene.manifest, &scene.shadow_maps, t.needs().shadow_maps);
        let rt_shadows = t.shadows.technique().ray_traced();
        if rt_shadows && plan.lights_used as usize > MAX_RT_SHADOW_LIGHTS {
            plan.warnings.push(format!(
                "{} light(s) are drawn without ray-traced shadows: at most {MAX_RT_SHADOW_LIGHTS} have them",
                plan.lights_used as usize - MAX_RT_SHADOW_LIGHTS
            ));
        }
        let rays = t.rays(&techniques::RayScene {
            diagonal: scene.diagonal(),
            lights_used: plan.lights_used as usize,
        });
        for l in &mut plan.lights {
            l.radius = match l.kind {
                LightKinds::POINT | LightKinds::SPOT => rays.light_radius.max(0.0),
                LightKinds::DIRECTIONAL => (rays.sun_degrees.max(0.0) * 0.5).to_radians(),
                _ => 0.0,
            };
        }
        let emissive = scene.reference.as_ref().map_or(0, |r| r.emissive_count);
        let rt_constants = RtConstants {
            emitters: scene.reference.as_ref().map_or(0, |r| r.emitter_count),
            emissive,
            ..rays.rt
        };
        let mut flags = if plan.shadows_bound && surface_maps { FrameFlags::SHADOW_MAPS } else { 0 };
        flags |= t.flags();
        if emissive == 0 {
            // Nothing for the direct light of emissive surfaces to sample: the composition skips
            // its image and GI counts what its first rays hit.
            flags &= !FrameFlags::RT_DIRECT;
        }
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let lights = host_buffer(gpu, "lights", bytemuck::cast_slice(&plan.lights), storage)?;
        let shadows = host_buffer(gpu, "shadows", bytemuck::cast_slice(&plan.shadows), storage)?;
        let frame_ubo = Buffer::new(
            gpu,
            "frame",
            std::mem::size_of::<FrameConstants>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let timestamps = TimestampPool::new(gpu, frame.passes.len() as u32 + 1)?;
        let warnings = plan.warnings.clone();
        let mut renderer = Renderer {
            frame,
            frame_ubo,
            lights,
            shadows,
            plan,
            rt_constants,
            accumulated: 0,
            last_view_proj: None,
            view_proj: glam::DMat4::IDENTITY,
            history: false,
            flags,
            lut_resolution: scene.brdf_lut.as_ref().map_or(0, |i| i.desc.width),
            sky: scene.manifest.sky.radiance,
            media_dimming: if t.dims_surfaces() { scene.media.as_ref().map_or(0, |m| m.count) } else { 0 },
            settings,
            timestamps,
            frame_count: 0,
            warnings,
        };
        renderer.bind(gpu, scene, dummies)?;
        Ok(renderer)
    }

    /// Points every pass at the scene and the current images.
    fn bind(&mut self, gpu: &Gpu, scene: &GpuScene, dummies: &Dummies) -> PlayResult {
        let shared = Shared {
            scene,
            frame_ubo: &self.frame_ubo,
            lights: &self.lights,
            shadows: &self.shadows,
            plan: &self.plan,
            dummies,
            images: &self.frame.images,
        };
        for p in &mut self.frame.passes {
            p.bind(gpu, &shared)?;
        }
        Ok(())
    }

    /// Points the passes at the scene's textures again once their finer levels are resident
    /// ([`GpuScene::use_refined_views`]; no submitted frame may still read the sets), and
    /// restarts the frame count, running average and histories: the frames after it are those
    /// of a scene loaded whole (bit for bit), none blending in a coarse one.
    pub fn textures_refined(&mut self, gpu: &Gpu, scene: &GpuScene, dummies: &Dummies) -> PlayResult {
        self.restart();
        self.bind(gpu, scene, dummies)
    }

    /// Forgets every frame so far: accumulation, histories and the frame count start again,
    /// so that the next frame is rendered as a session's first.
    pub fn restart(&mut self) {
        self.accumulated = 0;
        self.last_view_proj = None;
        self.frame_count = 0;
    }

    /// The frame's images.
    pub fn images(&self) -> &FrameImages {
        &self.frame.images
    }

    /// How the passes that read the texel buffer decode it (what their pipelines were
    /// specialized for).
    pub fn texel_decode(&self) -> TexelDecode {
        self.frame.decode
    }

    /// Names of the passes that run, in order.
    pub fn pass_names(&self) -> Vec<&'static str> {
        self.frame.passes.iter().map(|p| p.name()).collect()
    }

    /// Recreates the targets for a new size (the GPU must be idle).
    pub fn resize(
        &mut self,
        gpu: &Gpu,
        scene: &GpuScene,
        dummies: &Dummies,
        width: u32,
        height: u32,
    ) -> PlayResult {
        self.frame.resize(gpu, width.max(1), height.max(1))?;
        self.accumulated = 0;
        self.last_view_proj = None;
        self.bind(gpu, scene, dummies)
    }

    /// Writes the frame constants for `camera` (the previous frame must have finished).
    pub fn update(&mut self, camera: &Camera) -> PlayResult {
        let (w, h) = (self.frame.images.width, self.frame.images.height);
        let aa = self.settings.techniques.aa;
        let unjittered = camera.view_projection(w, h);
        let still = self.last_view_proj == Some(unjittered);
        if !aa.accumulates() || !still {
            self.accumulated = 0;
        }
        let jitter = if aa.temporal() { taa_jitter(self.frame_count) } else { [0.0; 2] };
        // The sample of pixel p lies at p + ½ + jitter: the projection moves the image by
        // −jitter (NDC x right, y up; image y down).
        let shift = glam::DMat4::from_translation(glam::DVec3::new(
            -2.0 * jitter[0] / w as f64,
            2.0 * jitter[1] / h as f64,
            0.0,
        ));
        let vp = shift * unjittered;
        let inverse = vp.inverse();
        let previous = self.last_view_proj.unwrap_or(unjittered);
        let reproject = (previous * inverse).as_mat4().to_cols_array();
        let history = self.last_view_proj.is_some();
        self.history = history;
        self.last_view_proj = Some(unjittered);
        self.view_proj = unjittered;
        let (view_proj, inv_view_proj) = (vp.as_mat4().to_cols_array(), inverse.as_mat4().to_cols_array());
        let p = camera.position.as_vec3();
        let (right, up, half) = camera.image_axes();
        let aspect = w as f64 / h as f64;
        let v4 = |v: glam::DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
        let constants = FrameConstants {
            view_proj,
            inv_view_proj,
            camera: [p.x, p.y, p.z, if camera.ortho.is_some() { 1.0 } else { 0.0 }],
            sky: [self.sky[0], self.sky[1], self.sky[2], self.media_dimming as f32],
            size: [w, h, self.plan.lights_used, self.flags],
            params: [
                2f32.powf(self.settings.exposure),
                self.lut_resolution as f32,
                self.frame_count as f32,
                self.rt_constants.max_roughness,
            ],
            // Perspective: tangents of the half fields of view; orthographic: half extents.
            camera_right: v4(right, half * aspect),
            camera_up: v4(up, half),
            camera_forward: v4(camera.forward, 0.0),
            reproject,
            jitter: [
                jitter[0] as f32,
                jitter[1] as f32,
                if still { 1.0 } else { 0.0 },
                if history { 0.0 } else { 1.0 },
            ],
        };
        self.frame_ubo.write(bytemuck::bytes_of(&constants))
    }

    /// Records one frame: every pass, a timestamp after each.
    pub fn record(&mut self, rec: &Recorder, scene: &GpuScene) {
        rec.reset_timestamps(&self.timestamps);
        rec.timestamp(&self.timestamps, 0);
        // With reprojected accumulation the passes write this frame's sample; the history pass
        // blends it.
        self.rt_constants.accumulated =
            if self.settings.techniques.reprojected_rays().is_some() { 0 } else { self.accumulated };
        self.rt_constants.seed = self.frame_count as u32;
        let Frame { passes, images, again, .. } = &mut self.frame;
        let again: &[usize] = if self.history { &[] } else { again };
        let see_through_area = passes::see_through::screen_area(
            scene.see_through_bounds,
            self.view_proj,
            images.width,
            images.height,
        );
        let mut ctx = FrameCtx { rec, images, scene, rt: &self.rt_constants, again: false, see_through_area };
        for i in 0..passes.len() {
            passes[i].record(&mut ctx);
            if again.last() == Some(&i) {
                // A frame without history: the screen-space passes again, over this frame's
                // light (timed with the last pass of the list: the direct pass, or the
                // see-through composite after it).
                ctx.again = true;
                for &j in again {
                    passes[j].record(&mut ctx);
                }
                ctx.again = false;
            }
            rec.timestamp(&self.timestamps, i as u32 + 1);
        }
        self.frame_count += 1;
        self.accumulated = (self.accumulated + 1).min(1 << 24);
    }

    /// Makes a frame image ready to be copied from (after [`Renderer::record`]) and returns it.
    pub fn copy_source(&mut self, rec: &Recorder, image: Readable) -> &Image {
        let target = match image {
            Readable::Display => passes::tonemap::DISPLAY,
            Readable::Radiance => passes::direct::RADIANCE,
        };
        self.frame.images.access(rec, &[(target, Access::Read(Use::TRANSFER_SRC))]);
        self.frame.images.get(&target)
    }

    /// Frames averaged into the ray-traced images at the current camera (after the last
    /// recorded frame).
    pub fn accumulated(&self) -> u32 {
        self.accumulated
    }

    /// GPU milliseconds of each pass of the last completed frame.
    pub fn pass_times(&self, gpu: &Gpu) -> PlayResult<PassTimes> {
        let ns = self.timestamps.read_ns(gpu)?;
        Ok(self
            .frame
            .passes
            .iter()
            .enumerate()
            .map(|(i, p)| (p.name(), (ns[i + 1] - ns[i]) * 1e-6))
            .collect())
    }
}

/// Length of the jitter sequence: the Halton points of one cycle cover the pixel evenly.
const JITTER_CYCLE: u64 = 16;

/// The radical inverse of `i` in `base`: the Halton sequence's coordinate.
fn radical_inverse(mut i: u64, base: u64) -> f64 {
    let (mut value, mut scale) = (0.0, 1.0);
    while i > 0 {
        scale /= base as f64;
        value += (i % base) as f64 * scale;
        i /= base;
    }
    value
}

/// Frame `n`'s sample offset from the pixel centre in pixels: the Halton (2, 3) point
/// 1 + n mod 16 in (−½, ½)² (the seed's Karis jitter spans ±⅛ pixel; the whole pixel is
/// what makes the converged history the box-filtered, supersampled image).
pub fn taa_jitter(n: u64) -> [f64; 2] {
    let i = 1 + n % JITTER_CYCLE;
    [radical_inverse(i, 2) - 0.5, radical_inverse(i, 3) - 0.5]
}

/// Which image of a frame to read back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Readable {
    /// The tone-mapped RGBA8 image.
    Display,
    /// The linear RGBA32F radiance.
    Radiance,
}

/// A host-visible copy of one of a frame's images (its buffer released when dropped).
#[derive(Debug)]
pub struct Readback {
    /// The pixels, tightly packed.
    pub buffer: Buffer,
    /// Which image.
    pub image: Readable,
}

impl Readback {
    /// A buffer for `image` of targets of `width` × `height`.
    pub fn new(gpu: &Gpu, image: Readable, width: u32, height: u32) -> PlayResult<Readback> {
        let texel = if image == Readable::Display { 4 } else { 16 };
        let size = width as u64 * height as u64 * texel;
        let buffer =
            Buffer::new(gpu, "readback", size, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?;
        Ok(Readback { buffer, image })
    }

    /// Records the copy of the image into the buffer (after the frame).
    pub fn record(&self, rec: &Recorder, renderer: &mut Renderer) {
        let img = renderer.copy_source(rec, self.image);
        rec.copy_from_image(img, &self.buffer);
        rec.memory_barrier(
            vk::PipelineStageFlags2::TRANSFER,
            vk::AccessFlags2::TRANSFER_WRITE,
            vk::PipelineStageFlags2::HOST,
            vk::AccessFlags2::HOST_READ,
        );
    }
}
