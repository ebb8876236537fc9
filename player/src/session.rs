//! Opening a file for playback: device, pipelines and upload (the last two in parallel), then
//! frames. Every front end goes through here, and so does the load-time breakdown.
//!
//! With [`PipelineStart::Progressive`] and ray-traced techniques, the first frames come from a
//! fallback ([`crate::render::Techniques::fallback`]: no ray-traced pass, so its pipelines compile in
//! milliseconds) while the requested techniques' pipelines compile on a thread of their own
//! ([`FrameBuild`]); the session switches to them at the first frame after they are ready, or
//! when asked to wait ([`Session::finish_pipelines`]: headless output and benchmarks, whose
//! frames must all show the requested techniques).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use kiln_format::error::ErrorKind;
use kiln_format::read::{Checksums, KilnFile};
use kiln_format::sections;

use crate::camera::{Camera, CameraOverride, CameraPath};
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{CommandPool, Gpu, GpuOptions, Recorder, Semaphore, SemaphoreOp};
use crate::render::Needs;
use crate::render::background::{Built, FrameBuild};
use crate::render::frame::{Frame, SceneTraits};
use crate::render::techniques::Effect;
use crate::render::{Dummies, PassTimes, Readable, Readback, RenderSettings, Renderer, Techniques};
use crate::scene::upload::Uploader;
use crate::scene::{GpuScene, Prepared, TextureUpload};

/// What to open and how.
#[derive(Debug, Clone)]
pub struct SessionOptions {
    /// The `.kiln` file.
    pub file: PathBuf,
    /// Device options.
    pub gpu: GpuOptions,
    /// Rendering options.
    pub render: RenderSettings,
    /// Image size.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Camera override.
    pub camera: Option<CameraOverride>,
    /// Poses the frames of a headless or benchmark run move through (instead of `camera`).
    pub camera_path: Option<CameraPath>,
    /// The image frames can be copied back from (headless output).
    pub readback: Option<Readable>,
    /// Whether the first frames wait for every pipeline.
    pub pipelines: PipelineStart,
    /// Whether the first frame waits for every texture level.
    pub textures: TextureUpload,
}

/// When the first frame is rendered, relative to the pipelines of the chosen techniques.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PipelineStart {
    /// After every pipeline of the chosen techniques is built.
    #[default]
    Complete,
    /// When ray-traced techniques are chosen, from their fallback while their pipelines compile
    /// on another thread (`kiln-play`'s default; the first run on a machine compiles them for
    /// seconds). Frames switch to the chosen techniques when the pipelines are ready.
    Progressive,
}

impl SessionOptions {
    /// `file` at `width` × `height` with the default device and render settings.
    pub fn new(file: impl Into<PathBuf>, width: u32, height: u32) -> SessionOptions {
        SessionOptions {
            file: file.into(),
            gpu: GpuOptions::default(),
            render: RenderSettings::default(),
            width,
            height,
            camera: None,
            camera_path: None,
            readback: None,
            pipelines: PipelineStart::default(),
            textures: TextureUpload::default(),
        }
    }
}

/// An effect the first frames showed with another technique than the chosen one.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Substitute {
    /// The effect (`shadows`, `ao`, ...).
    pub effect: &'static str,
    /// The chosen technique.
    pub requested: &'static str,
    /// The technique shown until the chosen one's pipelines were ready.
    pub shown: &'static str,
}

/// One pass's pipeline build.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PassBuild {
    /// The pass.
    pub pass: &'static str,
    /// Milliseconds its constructor took (on a thread of its own).
    pub ms: f64,
}

/// Milliseconds spent in each step of loading (wall clock, this process).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct LoadTimes {
    /// Loader, instance and device creation.
    pub instance_and_device_ms: f64,
    /// Mapping the file and validating header, table and manifest.
    pub open_file_ms: f64,
    /// Validating the file, verifying the checksums of what is uploaded, sorting indices
    /// (parallel with instance and device creation).
    pub prepare_ms: f64,
    /// Decoding compressed sections, summed over threads (each once, within `prepare_ms` and
    /// later uploads; 0 when the file stores every section as is).
    pub decode_ms: f64,
    /// Wall time of verifying and decoding the sections the first frame reads, on all cores
    /// (within `prepare_ms`, so parallel with instance and device creation).
    pub decode_wall_ms: f64,
    /// Building the first frame's pipelines and allocating its targets (parallel with the
    /// upload): the fallback's when there is one.
    pub pipelines_ms: f64,
    /// Each pass of the first frame and the milliseconds its pipelines took to build on their
    /// own thread (the slowest bounds `pipelines_ms`).
    pub pipelines_by_pass: Vec<PassBuild>,
    /// Building the chosen techniques' pipelines and targets: `pipelines_ms` without a
    /// fallback; with one, on their own thread, from the device's creation on.
    pub full_pipelines_ms: f64,
    /// Recording and submitting every upload before the first frame, until the GPU finished
    /// them.
    pub upload_ms: f64,
    /// Sections (as `kiln inspect` names them) that only the chosen techniques read, uploaded
    /// after the fallback's first frame instead of before it (empty without a fallback: the
    /// first frame reads every section uploaded).
    pub after_first_frame: Vec<String>,
    /// Preparing and uploading those sections after the first frame, until the GPU finished.
    pub rest_upload_ms: f64,
    /// Bytes of texture levels uploaded before the first frame: with streaming, each
    /// texture's levels from the first at most `COARSE_SIDE` (256) texels on a side down to
    /// 1×1; without, every level.
    pub coarse_texture_bytes: u64,
    /// Bytes of the finer texture levels uploaded after the first frame (0 without streaming).
    pub refined_texture_bytes: u64,
    /// From process start until every texture level was resident and the raster passes
    /// sampled the full chains (with streaming, after the first frame).
    pub textures_refined_since_start_ms: f64,
    /// Bytes uploaded.
    pub upload_bytes: u64,
    /// Sections uploaded / skipped.
    pub sections_uploaded: usize,
    /// Sections not uploaded (no enabled pass reads them).
    pub sections_skipped: usize,
    /// Rendering the first frame (submit to done).
    pub first_frame_gpu_ms: f64,
    /// From process start until everything the passes read was resident (after the first
    /// frame when sections were left for after it).
    pub resident_since_start_ms: f64,
    /// From process start until the first frame finished on the GPU.
    pub first_frame_since_start_ms: f64,
    /// From process start until the first frame's output was written (headless).
    pub first_output_since_start_ms: f64,
    /// From process start until the chosen techniques could render: their pipelines built and
    /// the scene resident.
    pub full_ready_since_start_ms: f64,
    /// From process start until the first frame of the chosen techniques finished on the GPU
    /// (`first_frame_since_start_ms` without a fallback).
    pub full_frame_since_start_ms: f64,
    /// The effects the first frames showed with other techniques (empty: every frame showed
    /// the chosen ones).
    pub fallback: Vec<Substitute>,
    /// Frames rendered with the fallback.
    pub fallback_frames: u32,
    /// From the first fallback frame's submission until the switch to the chosen techniques.
    pub fallback_shown_ms: f64,
}

/// An open file, ready to render. Dropping it waits for the GPU and for the pipeline thread,
/// then drops what it holds, the device last.
pub struct Session {
    /// Camera used by the next frame.
    pub camera: Camera,
    /// Load breakdown.
    pub times: LoadTimes,
    /// Notes for the user.
    pub warnings: Vec<String>,
    /// What happened while loading that is no problem (the fallback shown, the switch from it),
    /// in order.
    pub notes: Vec<String>,
    /// The scene.
    pub scene: GpuScene,
    /// The renderer: the fallback's while [`Session::showing_fallback`].
    pub renderer: Renderer,
    /// Where [`Session::frame`] copies the frame when asked to.
    pub readback: Option<Readback>,
    /// The chosen techniques' frame being built while the fallback renders.
    upgrade: Option<Upgrade>,
    dummies: Dummies,
    pool: CommandPool,
    timeline: Semaphore,
    ready: u64,
    waited: bool,
    _file: KilnFile,
    start: Instant,
    resident: Instant,
    /// What the passes read, when sections of it wait for [`Session::upload_rest`].
    rest: Option<Needs>,
    fallback_since: Option<Instant>,
    /// The device (dropped last, after everything made on it; shared with the thread that
    /// builds pipelines).
    pub gpu: Arc<Gpu>,
}

/// The chosen techniques' frame, building, and the settings to render it with.
#[derive(Debug)]
struct Upgrade {
    build: FrameBuild,
    settings: RenderSettings,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session").field("gpu", &self.gpu.name).field("scene", &self.scene).finish()
    }
}

/// What the first frame shows and reads, decided once the file is validated.
struct Plan {
    /// The chosen techniques, less the ray-traced ones when the file has no BVH.
    requested: Techniques,
    /// What stands in for them while their pipelines compile, if anything.
    fallback: Option<Techniques>,
    /// What the first frame reads (the fallback's needs when there is one).
    first_needs: Needs,
    warnings: Vec<String>,
}

impl Plan {
    fn of(render: &RenderSettings, progressive: bool, file: &KilnFile) -> PlayResult<Plan> {
        let manifest = file.manifest().map_err(|e| PlayError::new(Exit::BadInput, e.to_string()))?;
        let has_bvh = file.find(sections::BVH_NODES, 0).is_some_and(|s| s.entry.raw_size > 0);
        let mut warnings = Vec::new();
        let mut render = *render;
        if render.techniques.ray_traced() && !has_bvh {
            warnings.push("the ray-traced passes are off: the file has no BVH".to_string());
            render.techniques = render.techniques.without_rays();
        }
        let requested = render.techniques;
        let fallback = if progressive { requested.fallback(!manifest.shadow_maps.is_empty()) } else { None };
        // The first frame waits only for what it reads; the rest uploads after it.
        let first_needs = match fallback {
            Some(f) => RenderSettings { techniques: f, ..render }.needs(),
            None => render.needs(),
        };
        Ok(Plan { requested, fallback, first_needs, warnings })
    }
}

/// Whether a material of the file emits (what the emissive triangles' table is made of).
pub fn has_emission(file: &KilnFile) -> PlayResult<bool> {
    let materials: &[kiln_format::sections::GpuMaterial] = file
        .pod(sections::MATERIALS, 0)
        .map_err(|e| PlayError::new(Exit::BadInput, e.to_string()))?
        .unwrap_or(&[]);
    Ok(materials.iter().any(|m| m.emission.iter().any(|&e| e > 0.0)))
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

/// Opens a `.kiln` file, mapping format errors to exit codes with the path in the message.
pub fn open_file(path: &Path) -> PlayResult<KilnFile> {
    KilnFile::open(path, Checksums::OnAccess).map_err(|e| {
        let exit = match e.kind {
            ErrorKind::Io(_) | ErrorKind::NotAFile => Exit::Io,
            _ => Exit::BadInput,
        };
        PlayError::new(exit, format!("{}: {e}", path.display()))
    })
}

impl Session {
    /// Opens `options.file` on a new device. `start` is the process start (for the breakdown).
    pub fn open(options: &SessionOptions, start: Instant) -> PlayResult<Session> {
        let mut times = LoadTimes::default();
        let t = Instant::now();
        let file = open_file(&options.file)?;
        times.open_file_ms = ms(t);
        let mut render = options.render;
        if !has_emission(&file)? {
            // Nothing emits: the direct light of emissive surfaces would sample nothing; its
            // passes, their pipelines and the sections only they read (the BVH) are skipped.
            render.techniques.set(Effect::Direct, "none", &[]).map_err(|e| PlayError::new(Exit::Usage, e))?;
        }
        let progressive = options.pipelines == PipelineStart::Progressive;
        // The fallback's sections are uploaded too (the shadow maps that stand in for
        // ray-traced shadows); whether the file has maps is known once it is validated.
        let needs = match render.techniques.fallback(true) {
            Some(f) if progressive => render.needs().union(f.needs()),
            _ => render.needs(),
        };
        // The CPU side of loading (validation, checksums, index sorting, decoding what the first
        // frame reads) runs while the driver creates the device, which on some drivers takes
        // well over 100 ms.
        let (gpu, prepared) = std::thread::scope(|s| {
            let prep = s.spawn(|| {
                let t = Instant::now();
                let plan = Plan::of(&render, progressive, &file)?;
                let (prepared, decode_ms) = Prepared::new(&file, needs, plan.first_needs)?;
                Ok::<_, PlayError>((prepared, plan, ms(t), decode_ms))
            });
            let t = Instant::now();
            let gpu = Gpu::new(&options.gpu).map(|g| (g, ms(t)));
            let prepared = prep
                .join()
                .unwrap_or_else(|_| Err(PlayError::new(Exit::BadInput, "validating the file panicked")));
            (gpu, prepared)
        });
        let (gpu, device_ms) = gpu?;
        let gpu = Arc::new(gpu);
        times.instance_and_device_ms = device_ms;
        let (prepared, plan, prepare_ms, decode_wall_ms) = prepared?;
        times.prepare_ms = prepare_ms;
        times.decode_wall_ms = decode_wall_ms;
        let timeline = gpu.timeline_semaphore()?;
        let upload_start = Instant::now();
        // Pipelines compile on one thread while the other streams the file to the GPU.
        let (width, height, readback) = (options.width, options.height, options.readback);
        let Plan { requested, fallback, first_needs, mut warnings } = plan;
        render.techniques = requested;
        let traits = SceneTraits::of(prepared.manifest(), prepared.see_through_bounds().is_some());
        let decode = prepared.texel_decode();
        // The chosen techniques' pipelines behind a fallback compile on a thread of their own,
        // started first: they take longest. Dropped on an error below, it waits for the thread
        // and drops what it built.
        let background = match fallback {
            Some(_) => Some(FrameBuild::spawn(&gpu, requested, traits, decode, width, height)?),
            None => None,
        };
        let first = fallback.unwrap_or(requested);
        // On an error below, what was made is dropped on return: the GPU is done with it (the
        // upload waits for itself; nothing else was submitted).
        let (pipelines, loaded) = std::thread::scope(|s| {
            let pipes = s.spawn(|| {
                let t = Instant::now();
                // The frame's targets too: allocating them costs milliseconds on some drivers.
                let frame = Frame::new(&gpu, &first, traits, decode, width, height)?;
                let rb = readback.map(|r| Readback::new(&gpu, r, width, height)).transpose()?;
                Ok((frame, rb, ms(t), Instant::now()))
            });
            let loaded = (|| -> PlayResult<(GpuScene, Dummies, u64, u64)> {
                // Dropped on an error, the ring waits for what it submitted (`GpuScene::load`
                // waits for the GPU itself before it drops what it made).
                let mut up = Uploader::new(&gpu, ring_bytes(&gpu), timeline.raw)?;
                let dummies = Dummies::new(&gpu, &mut up)?;
                let scene = GpuScene::load(&gpu, &file, &prepared, first_needs, options.textures, &mut up)?;
                let flushed = up.flush();
                let bytes = up.bytes;
                let finished = up.finish();
                let ready = flushed?;
                finished?;
                Ok((scene, dummies, ready, bytes))
            })();
            let pipes =
                pipes.join().unwrap_or_else(|_| Err(PlayError::new(Exit::Gpu, "pipeline creation panicked")));
            (pipes, loaded)
        });
        let scene_deferred = loaded.as_ref().is_ok_and(|(scene, ..)| scene.deferred());
        let (scene, dummies, ready, bytes) = loaded?;
        times.upload_ms = ms(upload_start);
        times.decode_ms = file.decode_time().as_secs_f64() * 1e3;
        times.upload_bytes = bytes;
        times.sections_uploaded = scene.sections.iter().filter(|s| s.uploaded).count();
        times.sections_skipped = scene.sections.len() - times.sections_uploaded;
        times.after_first_frame =
            scene.sections.iter().filter(|s| s.after_first_frame).map(|s| s.later_name()).collect();
        times.resident_since_start_ms = ms(start);
        times.coarse_texture_bytes = scene.coarse_texture_bytes;
        if !scene.coarse_views() {
            times.textures_refined_since_start_ms = times.resident_since_start_ms;
        }
        let resident = Instant::now();
        let (frame, readback, pipelines_ms, pipelines_done) = pipelines?;
        times.pipelines_ms = pipelines_ms;
        times.pipelines_by_pass = frame.build_ms.iter().map(|&(pass, ms)| PassBuild { pass, ms }).collect();
        if background.is_none() {
            times.full_pipelines_ms = pipelines_ms;
            times.full_ready_since_start_ms =
                pipelines_done.max(resident).duration_since(start).as_secs_f64() * 1e3;
        }
        let camera = Camera::initial(&scene.manifest, options.camera)?;
        let renderer =
            Renderer::new(&gpu, frame, &dummies, &scene, RenderSettings { techniques: first, ..render })?;
        let pool = CommandPool::new(&gpu, gpu.family)?;
        warnings.extend(renderer.warnings.iter().cloned());
        let mut notes = Vec::new();
        if let Some(f) = &fallback {
            times.fallback = requested
                .differences(f)
                .into_iter()
                .map(|(effect, requested, shown)| Substitute { effect: effect.name(), requested, shown })
                .collect();
            notes.push(format!(
                "the ray-traced passes' pipelines compile in the background; until they are ready frames show {}",
                substitutes(&times.fallback)
            ));
            if !times.after_first_frame.is_empty() {
                notes.push(format!(
                    "the first frame does not wait for the sections only the chosen techniques read: {}",
                    times.after_first_frame.join(", ")
                ));
            }
        }
        warnings.extend(render.techniques.warnings(&scene.manifest));
        Ok(Session {
            camera,
            times,
            warnings,
            notes,
            scene,
            renderer,
            readback,
            upgrade: background.map(|build| Upgrade { build, settings: render }),
            dummies,
            pool,
            timeline,
            ready,
            waited: false,
            _file: file,
            start,
            resident,
            rest: scene_deferred.then_some(needs),
            fallback_since: None,
            gpu,
        })
    }

    /// Uploads the sections the first frame did not wait for, if any are left (each frame
    /// calls it after the first, and the switch to the chosen techniques before it); returns
    /// when they are resident. The next frame waits for them on the GPU too.
    pub fn upload_rest(&mut self) -> PlayResult {
        let Some(needs) = self.rest.take() else { return Ok(()) };
        let t = Instant::now();
        let (prepared, _) = Prepared::new(&self._file, needs, needs)?;
        let mut up = Uploader::new(&self.gpu, ring_bytes(&self.gpu), self.timeline.raw)?.after(self.ready);
        let loaded = self.scene.load_rest(&self.gpu, &self._file, &prepared, &mut up);
        let flushed = up.flush();
        let bytes = up.bytes;
        let finished = up.finish();
        loaded?;
        self.ready = flushed?;
        finished?;
        // Made visible to the frames' queue by the timeline, as the first upload is.
        self.waited = false;
        self.times.rest_upload_ms = ms(t);
        self.times.upload_bytes += bytes;
        self.times.resident_since_start_ms = ms(self.start);
        self.resident = Instant::now();
        if self.scene.coarse_views() {
            self.use_refined_textures()?;
        }
        Ok(())
    }

    /// Switches the raster passes from the textures' coarse views to their full chains, whose
    /// finer levels [`Session::upload_rest`] made resident. The material sets are rewritten in
    /// place (they are not update-after-bind), so no submitted frame may still read them: this
    /// waits, once, for the frame in flight (there is one at most: each frame's `begin` waits
    /// for the previous), and only then releases the coarse views.
    fn use_refined_textures(&mut self) -> PlayResult {
        self.pool.wait(&self.gpu)?;
        self.scene.use_refined_views();
        self.renderer.textures_refined(&self.gpu, &self.scene, &self.dummies)?;
        let t = &mut self.times;
        t.refined_texture_bytes = self.scene.fine_texture_bytes;
        t.textures_refined_since_start_ms = ms(self.start);
        self.notes.push(format!(
            "textures streamed: the first frame sampled their coarse levels ({:.1} MiB); the finer ones ({:.1} MiB) were resident {:.0} ms after start",
            t.coarse_texture_bytes as f64 / (1 << 20) as f64,
            t.refined_texture_bytes as f64 / (1 << 20) as f64,
            t.textures_refined_since_start_ms
        ));
        Ok(())
    }

    /// Whether the next frame is not yet what every later frame shows: it would come from a
    /// fallback, or sections (a texture's finer levels) are still to upload after it.
    /// Headless output and benchmarks render one such frame, then [`Session::finish_pipelines`].
    pub fn provisional(&self) -> bool {
        self.upgrade.is_some() || self.rest.is_some()
    }

    /// Starts accumulation and histories again: the next frame is rendered as the first of a
    /// session that waited for everything.
    pub fn restart(&mut self) {
        self.renderer.restart();
    }

    /// Whether frames come from the fallback (the chosen techniques' pipelines are still
    /// building, or built but not yet switched to).
    pub fn showing_fallback(&self) -> bool {
        self.upgrade.is_some()
    }

    /// Waits for the chosen techniques' pipelines, if they are still building, and switches to
    /// them, and uploads what the first frame did not wait for: every frame after this shows
    /// the chosen techniques with every texture level.
    pub fn finish_pipelines(&mut self) -> PlayResult {
        self.switch(true)?;
        self.upload_rest()
    }

    /// Switches from the fallback to the chosen techniques when their frame is built (with
    /// `wait`, waiting for it): waits for the GPU, binds the new frame at the current size,
    /// releases the fallback's. The running average and histories start anew, as after a
    /// resize. An error building the chosen techniques' pipelines is returned here.
    fn switch(&mut self, wait: bool) -> PlayResult {
        match &self.upgrade {
            Some(u) if wait || u.build.is_finished() => {}
            _ => return Ok(()),
        }
        self.upload_rest()?;
        let Some(Upgrade { build, settings }) = self.upgrade.take() else { return Ok(()) };
        let Built { mut frame, ms: built_ms, done } = build.join()?;
        let images = self.renderer.images();
        let (width, height) = (images.width, images.height);
        self.gpu.wait_idle()?;
        if (frame.images.width, frame.images.height) != (width, height) {
            frame.resize(&self.gpu, width, height)?;
        }
        let full = Renderer::new(&self.gpu, frame, &self.dummies, &self.scene, settings)?;
        // The fallback's renderer goes: the GPU is idle (waited above), and the new frame has
        // not been submitted yet.
        drop(std::mem::replace(&mut self.renderer, full));
        let t = &mut self.times;
        t.full_pipelines_ms = built_ms;
        t.full_ready_since_start_ms = done.max(self.resident).duration_since(self.start).as_secs_f64() * 1e3;
        t.fallback_shown_ms = self.fallback_since.map_or(0.0, ms);
        for w in &self.renderer.warnings {
            if !self.warnings.contains(w) {
                self.warnings.push(w.clone());
            }
        }
        self.notes.push(format!(
            "the ray-traced passes' pipelines were ready {:.0} ms after start ({:.0} ms to build); {} frame(s) over {:.0} ms showed {}",
            t.full_ready_since_start_ms,
            t.full_pipelines_ms,
            t.fallback_frames,
            t.fallback_shown_ms,
            substitutes(&t.fallback)
        ));
        Ok(())
    }

    /// Renders one frame and waits for it; with `read`, copies it into [`Session::readback`].
    /// Returns the passes' GPU times.
    pub fn frame(&mut self, read: bool) -> PlayResult<PassTimes> {
        let t = Instant::now();
        let readback = if read { self.readback.take() } else { None };
        let submitted = self.record_and_submit(
            |rec, renderer| {
                if let Some(r) = &readback {
                    r.record(rec, renderer);
                }
            },
            &[],
            &[],
        );
        if readback.is_some() {
            self.readback = readback;
        }
        submitted?;
        self.pool.wait(&self.gpu)?;
        let since_start = ms(self.start);
        if self.times.first_frame_gpu_ms == 0.0 {
            self.times.first_frame_gpu_ms = ms(t);
            self.times.first_frame_since_start_ms = since_start;
        }
        if self.upgrade.is_none() && self.times.full_frame_since_start_ms == 0.0 {
            self.times.full_frame_since_start_ms = since_start;
        }
        let times = self.renderer.pass_times(&self.gpu);
        self.upload_rest()?;
        times
    }

    /// Records a frame plus `extra` commands and submits it with extra semaphores (the window
    /// adds its swapchain's); the first frame also waits for the upload. Switches from the
    /// fallback first when the chosen techniques' pipelines are ready.
    pub fn record_and_submit(
        &mut self,
        extra: impl FnOnce(&Recorder, &mut Renderer),
        wait: &[SemaphoreOp],
        signal: &[SemaphoreOp],
    ) -> PlayResult {
        self.switch(false)?;
        if self.upgrade.is_some() {
            self.times.fallback_frames += 1;
            self.fallback_since.get_or_insert_with(Instant::now);
        }
        let rec = self.pool.begin(&self.gpu)?;
        self.renderer.update(&self.camera)?;
        self.renderer.record(&rec, &self.scene);
        extra(&rec, &mut self.renderer);
        let mut waits = wait.to_vec();
        if !self.waited {
            waits.push(SemaphoreOp::timeline(self.timeline.raw, self.ready));
            self.waited = true;
        }
        self.pool.submit(&self.gpu, &waits, signal)
    }

    /// Looks through `pose` (the file's camera moved as `--camera` moves it; `None`: the file's
    /// camera itself).
    pub fn look(&mut self, pose: Option<CameraOverride>) -> PlayResult {
        let m = &self.scene.manifest;
        self.camera = Camera::initial(m, pose)?;
        Ok(())
    }

    /// For frame `i` of `frames` of a run along `options`' camera path, looks through its pose
    /// (nothing without a path).
    pub fn follow(&mut self, options: &SessionOptions, i: u32, frames: u32) -> PlayResult {
        match &options.camera_path {
            Some(path) => self.look(Some(path.at(i, frames))),
            None => Ok(()),
        }
    }

    /// Waits for the last submitted frame.
    pub fn wait(&self) -> PlayResult {
        self.pool.wait(&self.gpu)
    }

    /// GPU times of the last finished frame.
    pub fn pass_times(&self) -> PlayResult<PassTimes> {
        self.renderer.pass_times(&self.gpu)
    }

    /// Milliseconds since process start.
    pub fn since_start_ms(&self) -> f64 {
        ms(self.start)
    }

    /// Changes the image size (waits for the GPU).
    pub fn resize(&mut self, width: u32, height: u32) -> PlayResult {
        self.gpu.wait_idle()?;
        self.renderer.resize(&self.gpu, &self.scene, &self.dummies, width, height)
    }

    /// Validation-layer errors so far.
    pub fn validation_errors(&self) -> u32 {
        self.gpu.validation_errors()
    }

    /// Releases everything and returns the validation errors, including those the layer reports
    /// while the device is destroyed (objects never freed).
    pub fn close(self) -> u32 {
        let counts = self.gpu.validation.clone();
        drop(self);
        counts.errors.load(std::sync::atomic::Ordering::Relaxed)
    }
}

impl Drop for Session {
    /// What a frame or an upload uses may be dropped only once the GPU is done with it: waits
    /// for the GPU; the fields are dropped after this, the device (`gpu`, the last) after
    /// everything made on it.
    fn drop(&mut self) {
        let _ = self.gpu.wait_idle();
        // Waits for the pipeline thread and drops what it built, so that the thread's hold on
        // the device ends before `gpu` is dropped.
        self.upgrade = None;
    }
}

/// "shadows shadowmap for rt, ao none for rt": what stood in for what.
fn substitutes(list: &[Substitute]) -> String {
    let each: Vec<String> =
        list.iter().map(|s| format!("{} {} for {}", s.effect, s.shown, s.requested)).collect();
    each.join(", ")
}

/// Bytes of each half of the staging ring.
fn ring_bytes(gpu: &Gpu) -> u64 {
    if gpu.is_cpu() { 8 << 20 } else { 16 << 20 }
}
