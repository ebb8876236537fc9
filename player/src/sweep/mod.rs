//! `kiln-bench`: every technique as a point of (GPU time, error against a path-traced
//! reference), per effect, with the Pareto front.
//!
//! For each camera: the reference (two independent halves, cached; [`truth`]), then every
//! configuration of the [`plan`] in a session of its own ([`measure`]): its image at each frame
//! count it is measured at, compared with the reference ([`kiln_metrics`]), and its GPU time per
//! frame over many frames. Effect charts hold the other effects fixed ([`plan::fixed`]), so that
//! two points of a chart differ by their effect alone. [`report`] writes the JSON, CSV, charts
//! and page.

pub mod budget;
pub mod cli;
pub mod diff;
pub mod measure;
pub mod plan;
pub mod report;
pub mod results;
pub mod truth;

use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use kiln_format::linespace::GridHeader;
use kiln_format::sections::{BVH_NODES, GRID};
use xxhash_rust::xxh3::Xxh3;

use crate::camera::{Camera, CameraOverride, CameraPath};
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Gpu, GpuOptions};
use crate::render::{Effect, Purpose, RenderSettings, Techniques};
use crate::scene::TextureUpload;
use crate::session::{PipelineStart, SessionOptions, open_file};

use measure::{Measured, Timing, measure};
use plan::{Config, Offers, Plan, Request, Skipped, Target};
use results::{Figures, Point, Results, SceneInfo, TimingInfo};
use truth::Reference;

/// The largest image side a sweep accepts (the reference accumulates in RGBA32F).
pub const MAX_SIDE: u32 = 8192;

/// Everything a sweep needs to know.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// The `.kiln` file.
    pub file: PathBuf,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Cameras (`None`: the file's camera); at least one.
    pub cameras: Vec<Option<CameraOverride>>,
    /// A moving camera instead of `cameras`.
    pub camera_path: Option<PathSweep>,
    /// What to sweep.
    pub request: Request,
    /// Reference samples per pixel (two halves of half each).
    pub reference_spp: u32,
    /// Frames timed per configuration.
    pub timing: Timing,
    /// Output folder (also the reference cache).
    pub out: PathBuf,
    /// Device options.
    pub gpu: GpuOptions,
    /// Write every measured image (EXR) and the reference into `OUT/images/`.
    pub keep_images: bool,
    /// Show progress bars.
    pub progress: bool,
}

/// A sweep along a camera path: every configuration renders `frames` frames along `path` and is
/// measured at the last, against the reference at the last pose.
#[derive(Debug, Clone)]
pub struct PathSweep {
    /// The poses.
    pub path: CameraPath,
    /// Frames the path takes.
    pub frames: u32,
    /// Its name in the report (the file's stem).
    pub name: String,
}

impl PathSweep {
    /// The pose of the last frame, where the images are compared.
    pub fn last_pose(&self) -> CameraOverride {
        self.path.at(self.frames - 1, self.frames)
    }
}

/// A sweep's outcome: the results, and points that could not be measured.
#[derive(Debug)]
pub struct Outcome {
    /// The results (every point that was measured).
    pub results: Results,
    /// Configurations that failed (a GPU error, an image with NaN or infinity), with why.
    pub failures: Vec<Skipped>,
}

/// What the file offers, its scene name and content hash; refuses files the reference cannot
/// render.
fn inspect(options: &SweepOptions) -> PlayResult<(Offers, String, String, Vec<Camera>)> {
    let file = open_file(&options.file)?;
    let manifest = file
        .manifest()
        .map_err(|e| PlayError::new(Exit::BadInput, format!("{}: {e}", options.file.display())))?;
    let offers = Offers {
        bvh: file.find(BVH_NODES, 0).is_some(),
        shadow_maps: !manifest.shadow_maps.is_empty() && !manifest.lights.is_empty(),
        line_space: file
            .pod::<GridHeader>(GRID, 0)
            .ok()
            .flatten()
            .and_then(|h| h.first())
            .map_or(0, |h| h.variants),
        media: !manifest.media.is_empty(),
        emission: crate::session::has_emission(&file)?,
        lights: !manifest.lights.is_empty(),
        probes: file.find(kiln_format::sections::PROBE_GRID, 0).is_some(),
    };
    if !offers.bvh {
        return Err(PlayError::new(
            Exit::BadInput,
            format!(
                "{}: the file has no BVH, so the reference path tracer cannot render it (compile it without skipping the BVH)",
                options.file.display()
            ),
        ));
    }
    let mut h = Xxh3::new();
    h.update(file.bytes());
    let hash = format!("{:032x}", h.digest128());
    let mut cameras = Vec::new();
    for c in &options.cameras {
        cameras.push(
            Camera::initial(&manifest, *c)
                .map_err(|e| PlayError::new(Exit::Usage, format!("--camera: {e}")))?,
        );
    }
    Ok((offers, manifest.scene_name.clone(), hash, cameras))
}

/// Refuses sizes the reference cannot render, before any work.
pub fn check_size(width: u32, height: u32) -> PlayResult {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(PlayError::new(
            Exit::Usage,
            format!("--size {width}x{height}: each side must be 1..={MAX_SIDE} pixels"),
        ));
    }
    Ok(())
}

/// The camera's name in the results and the reference key.
fn camera_name(c: &Option<CameraOverride>) -> String {
    match c {
        None => "file".into(),
        Some(c) => {
            let mut v: Vec<String> = c.position.iter().chain(&c.target).map(|x| x.to_string()).collect();
            if let Some(f) = c.vfov_degrees {
                v.push(f.to_string());
            }
            v.join(",")
        }
    }
}

fn techniques_map(t: &Techniques) -> BTreeMap<String, String> {
    Effect::ALL.iter().map(|&e| (e.name().to_string(), t.name_of(e).to_string())).collect()
}

/// A bar on stderr when asked for, hidden otherwise.
fn bar(show: bool, len: u64) -> ProgressBar {
    let b = ProgressBar::with_draw_target(
        Some(len),
        if show { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() },
    );
    b.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} ETA {eta} {wide_msg}")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    b
}

/// `pixels` (linear RGB) as the metrics take them.
fn rgb_image(width: u32, height: u32, pixels: &[f32]) -> kiln_metrics::RgbImage<'_> {
    kiln_metrics::RgbImage { width, height, pixels }
}

/// The references one camera's charts need (one per bounce limit), rendered or from the cache.
fn camera_references(
    options: &SweepOptions,
    plan: &Plan,
    content_hash: &str,
    camera: &str,
    base: &SessionOptions,
    progress: &ProgressBar,
) -> PlayResult<BTreeMap<u32, Reference>> {
    let mut ref_options = base.clone();
    ref_options.render.purpose = Purpose::Reference;
    let mut refs = BTreeMap::new();
    for b in plan.configs.iter().map(|c| plan::bounces(c.target)) {
        if refs.contains_key(&b) {
            continue;
        }
        let half = options.reference_spp.div_ceil(2);
        let key = truth::key(content_hash, camera, options.width, options.height, half, b);
        progress.set_message(format!("reference, {} ({camera})", plan::transport(b)));
        let dir = options.out.join("reference");
        let reference = truth::obtain(&ref_options, camera, options.reference_spp, b, &key, &dir, |m| {
            progress.set_message(m.to_string())
        })?;
        progress.inc(1);
        if options.keep_images {
            let (w, h) = (options.width, options.height);
            report::keep_image(
                &options.out,
                camera,
                &format!("reference-{b}"),
                w,
                h,
                &reference.rgb,
                reference.info.spp,
            )?;
        }
        refs.insert(b, reference);
    }
    Ok(refs)
}

/// The points of one measured configuration: one per frame count whose image differs from the
/// previous count's, each compared with `reference`. An image that cannot be measured (NaN or
/// infinity) goes to `failures`.
fn points_of(
    options: &SweepOptions,
    config: &plan::Config,
    m: &Measured,
    fixed_passes: &[String],
    reference: &Reference,
    camera: &str,
    failures: &mut Vec<Skipped>,
) -> PlayResult<Vec<Point>> {
    let total = m.passes.last().expect("total is always there");
    let effect_ms = match config.target {
        Target::Frame => total.median_ms,
        Target::Effect(_) => m
            .passes
            .iter()
            .filter(|p| p.pass != "total" && !fixed_passes.contains(&p.pass))
            // From +0: an empty f64 sum is -0, which prints as "-0.000".
            .fold(0.0, |sum, p| sum + p.median_ms),
    };
    let (w, h) = (options.width, options.height);
    let mut points = Vec::new();
    for (i, (frames, rgb)) in m.images.iter().enumerate() {
        // An image the same as at the previous frame count (a technique that is deterministic
        // in this scene, e.g. ray-traced hard shadows) only costs more.
        if i > 0 && m.images[i - 1].1 == *rgb {
            continue;
        }
        let label = config.label(*frames);
        let (error, flip_map) =
            match kiln_metrics::compare_with_map(rgb_image(w, h, &reference.rgb), rgb_image(w, h, rgb)) {
                Ok((e, map)) => (Figures::from(e), map),
                Err(e) => {
                    failures.push(Skipped {
                        effect: config.target.name().into(),
                        technique: label,
                        reason: format!("cannot be measured: {e}"),
                    });
                    continue;
                }
            };
        if options.keep_images {
            let what = format!("{}-{label}", config.target);
            report::keep_image(&options.out, camera, &what, w, h, rgb, *frames)?;
            report::keep_error_map(&options.out, camera, &what, w, h, &flip_map)?;
        }
        points.push(Point {
            effect: config.target.name().into(),
            technique: config.technique.clone(),
            knobs: config.knobs.clone(),
            frames: *frames,
            label,
            camera: camera.to_string(),
            techniques: techniques_map(&config.techniques),
            frame_ms: total.median_ms,
            frame_p10_ms: total.p10_ms,
            frame_p90_ms: total.p90_ms,
            effect_ms,
            image_ms: total.median_ms * *frames as f64,
            passes: m.passes.clone(),
            error,
            reference_spp: reference.info.spp,
            reference_bounces: reference.info.bounces,
            noise_floor: reference.info.noise_floor,
            below_noise_floor: error.flip < reference.info.noise_floor.flip,
            on_front: false,
            regression: None,
        });
    }
    Ok(points)
}

/// Runs the sweep.
pub fn run(options: &SweepOptions) -> PlayResult<Outcome> {
    let started = Instant::now();
    check_size(options.width, options.height)?;
    options.request.check().map_err(|e| PlayError::new(Exit::Usage, e))?;
    if options.reference_spp < 2 {
        return Err(PlayError::new(
            Exit::Usage,
            "--reference-spp must be at least 2 (two independent halves)",
        ));
    }
    let (offers, scene_name, content_hash, _) = inspect(options)?;
    let mut plan: Plan = plan::plan(&options.request, &offers);
    let device = Gpu::new(&options.gpu)?.identity();
    let cameras: Vec<Option<CameraOverride>> = match &options.camera_path {
        Some(p) => {
            // One image per configuration: the path's last frame.
            for c in &mut plan.configs {
                c.checkpoints = vec![p.frames];
            }
            vec![Some(p.last_pose())]
        }
        None if options.cameras.is_empty() => vec![None],
        None => options.cameras.clone(),
    };
    let images_per_camera: u64 = plan.configs.iter().map(|c| c.checkpoints.len() as u64).sum::<u64>() + 3;
    let progress = bar(options.progress, images_per_camera * cameras.len() as u64);
    let mut points = Vec::new();
    let mut references = Vec::new();
    let mut warnings: Vec<String> = Vec::new();
    let mut failures = Vec::new();
    for camera in &cameras {
        let name = match &options.camera_path {
            // The reference is the last pose's: the name keys its cache.
            Some(p) => format!("path {} to {}", p.name, camera_name(camera)),
            None => camera_name(camera),
        };
        let base = SessionOptions {
            file: options.file.clone(),
            gpu: options.gpu.clone(),
            render: RenderSettings { techniques: plan.fixed, exposure: 0.0, purpose: Purpose::Frames },
            width: options.width,
            height: options.height,
            camera: *camera,
            camera_path: options.camera_path.as_ref().map(|p| p.path.clone()),
            readback: None,
            // Every frame is measured: none from a fallback, and none compiled for one.
            pipelines: PipelineStart::Complete,
            textures: TextureUpload::Whole,
        };
        let refs = camera_references(options, &plan, &content_hash, &name, &base, &progress)?;
        references.extend(refs.values().map(|r| r.info.clone()));
        if refs.values().any(|r| r.rgb.iter().all(|&v| v == 0.0)) {
            warnings.push(format!(
                "camera {name}: the reference is black: nothing lights what the camera sees (give the scene a [sky] or [[light]] in a sidecar); every error is 0"
            ));
        }
        // A configuration several charts share (the same techniques and frame counts) is
        // measured once. Its images are kept only while a later configuration will read them
        // again: memory stays bounded by those, whatever the number of configurations (every
        // image kept, a 1600 × 900 sweep held 17 MB per image and frame count).
        let key = |techniques: &Techniques, checkpoints: &[u32]| format!("{techniques:?} {checkpoints:?}");
        let mut uses: HashMap<String, usize> = HashMap::new();
        for c in &plan.configs {
            *uses.entry(key(&c.techniques, &c.checkpoints)).or_default() += 1;
        }
        let mut done: HashMap<String, Measured> = HashMap::new();
        let mut measure_once =
            |techniques: Techniques, checkpoints: &[u32], label: &str| -> PlayResult<Measured> {
                let k = key(&techniques, checkpoints);
                let left = uses.get_mut(&k).map_or(0, |n| {
                    *n = n.saturating_sub(1);
                    *n
                });
                if let Some(m) = done.get_mut(&k) {
                    progress.inc(checkpoints.len() as u64);
                    let images = if left == 0 { std::mem::take(&mut m.images) } else { m.images.clone() };
                    return Ok(Measured { images, passes: m.passes.clone(), warnings: m.warnings.clone() });
                }
                progress.set_message(label.to_string());
                let m = measure(&base, techniques, checkpoints, options.timing, || progress.inc(1))?;
                if left > 0 {
                    done.insert(k, m.clone());
                }
                Ok(m)
            };
        let fixed = measure_once(plan.fixed, &[1], "fixed frame")?;
        let fixed_passes: Vec<String> = fixed.passes.iter().map(|p| p.pass.clone()).collect();
        let mut camera_points = Vec::new();
        let mut measure_config = |config: &Config, points: &mut Vec<Point>| -> PlayResult {
            let label = config.label(*config.checkpoints.last().unwrap_or(&1));
            let m = match measure_once(config.techniques, &config.checkpoints, &label) {
                Ok(m) => m,
                Err(e) if e.exit == Exit::Gpu || e.exit == Exit::Unsupported => {
                    failures.push(Skipped {
                        effect: config.target.name().into(),
                        technique: config.technique.clone(),
                        reason: e.message,
                    });
                    return Ok(());
                }
                Err(e) => return Err(e),
            };
            for w in &m.warnings {
                if !warnings.contains(w) {
                    warnings.push(w.clone());
                }
            }
            let reference = &refs[&plan::bounces(config.target)];
            points.extend(points_of(options, config, &m, &fixed_passes, reference, &name, &mut failures)?);
            Ok(())
        };
        for config in &plan.configs {
            measure_config(config, &mut camera_points)?;
        }
        // One knob at a time, then the combinations the fronts point to.
        let mut marked = camera_points.clone();
        results::mark_front(&mut marked);
        let front: Vec<(Target, String, BTreeMap<String, String>)> = marked
            .iter()
            .filter(|p| p.on_front)
            .filter_map(|p| Target::parse(&p.effect).ok().map(|t| (t, p.technique.clone(), p.knobs.clone())))
            .collect();
        let refined = plan::refine(&options.request, &offers, &plan.configs, &front);
        progress.inc_length(refined.iter().map(|c| c.checkpoints.len() as u64).sum());
        for config in &refined {
            measure_config(config, &mut camera_points)?;
        }
        points.extend(camera_points);
    }
    progress.finish_and_clear();
    results::mark_front(&mut points);
    let fixed = techniques_map(&plan.fixed);
    let results = Results {
        schema: results::SCHEMA,
        tool: format!("kiln-bench {}", env!("CARGO_PKG_VERSION")),
        device,
        scene: SceneInfo { name: scene_name, file: options.file.display().to_string(), content_hash },
        width: options.width,
        height: options.height,
        timing: TimingInfo { warmup_frames: options.timing.warmup, frames: options.timing.frames },
        metrics: results::METRICS.into(),
        fixed,
        references,
        points,
        skipped: plan.skipped,
        warnings,
        sweep_seconds: started.elapsed().as_secs_f64(),
    };
    Ok(Outcome { results, failures })
}
