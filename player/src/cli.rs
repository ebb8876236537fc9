//! Command line of `kiln-play`.

use std::path::PathBuf;
use std::time::Instant;

use clap::builder::{PossibleValue, PossibleValuesParser};
use clap::{Parser, ValueEnum};

use crate::bench;
use crate::camera::{CameraOverride, CameraPath};
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{GpuOptions, default_cache_path, list_devices};
use crate::headless;
use crate::render::technique::{Effect, KnobValue, Techniques, catalogue, techniques_of};
use crate::render::{Purpose, RenderSettings};
use crate::scene::TextureUpload;
use crate::session::{PipelineStart, SessionOptions};
use crate::window;

const AFTER_HELP: &str = "\
Examples:
  kiln-play scene.kiln                                 open a window (WASD/QE fly, drag to look, Shift faster, Esc quits)
  kiln-play scene.kiln --headless --size 800x450 -o out.png
  kiln-play scene.kiln --headless -o radiance.exr       linear radiance, before exposure and tone mapping
  kiln-play scene.kiln --bench --json --size 1600x900  per-pass GPU times and the load breakdown
  kiln-play scene.kiln --bench --size 1600x900 --shadows rt --ao rt --reflections rt --light-radius 0.1
                                                       the hybrid ray-traced frame (seed 001)
  kiln-play scene.kiln --bench-rays --size 1600x900    traversal Mrays/s: primary, shadow, diffuse rays
  kiln-play scene.kiln --reference --spp 1024 -o ref.exr   the unbiased path-traced reference

Tone mapping: display = sRGB(ACES(2^exposure * radiance)), ACES being Narkowicz's fit
x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14) of the ACES filmic curve, per channel.

Exit codes: 0 success, 1 invalid or damaged .kiln file, 2 usage error, 3 unsupported (no Vulkan
loader, no suitable device, missing feature), 4 I/O error, 5 GPU failure or validation errors
(with --validate).";

/// Image size `WxH`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Size {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

impl std::str::FromStr for Size {
    type Err = String;
    fn from_str(s: &str) -> Result<Size, String> {
        let (w, h) =
            s.split_once(['x', 'X']).ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (e.g. 1280x720)"))?;
        let parse = |t: &str| t.trim().parse::<u32>().map_err(|_| format!("'{t}' is not a whole number"));
        let (width, height) = (parse(w)?, parse(h)?);
        if !(1..=16384).contains(&width) || !(1..=16384).contains(&height) {
            return Err(format!("{width}x{height}: each side must be 1..=16384"));
        }
        Ok(Size { width, height })
    }
}

/// The values `--EFFECT` takes: the catalogue's techniques of that effect, with their help.
fn techniques(effect: Effect) -> PossibleValuesParser {
    PossibleValuesParser::new(techniques_of(effect).map(|t| PossibleValue::new(t.name).help(t.help)))
}

/// `--reflection-res`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ReflectionResArg {
    /// One ray per pixel.
    Full,
    /// One ray per 2 × 2 pixels, upsampled with edge-aware weights.
    Half,
}

/// `--gi-structure` (order as the catalogue's choices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum GiStructureArg {
    /// The shaft's PNMT record.
    Pnmt,
    /// The shaft's candidate list.
    Candidates,
    /// The record's pre-illuminated radiance.
    Preillum,
}

/// `--ls-shadow-test` (order as the catalogue's choices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LsShadowTestArg {
    /// Exact tests in the cells holding the ray's ends.
    Ends,
    /// Exact tests wherever the shaft is filled.
    Filled,
}

/// `--ao-res` (order as the catalogue's choices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AoResArg {
    /// One sample set per pixel.
    Full,
    /// One per 2 × 2 pixels.
    Half,
}

/// `--media-res` (order as the catalogue's choices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MediaResArg {
    /// The screen's resolution.
    Full,
    /// Half on each axis.
    Half,
    /// A quarter on each axis.
    Quarter,
}

/// `--ssgi-mip` (order as the catalogue's choices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SsgiMipArg {
    /// One of each 2 × 2 block's texels, on a rotated grid (the seed's "fast").
    Nearest,
    /// The texel agreeing best with its neighbourhood (the seed's "precise").
    Voting,
}

/// `--ssgi-rotation` (order as the catalogue's choices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SsgiRotationArg {
    /// A random angle per texel (the seed's).
    Pixel,
    /// One per 8 × 8 texels (coherent reads).
    Tile,
}

/// `--ssgi-falloff` (order as the catalogue's choices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OffOnArg {
    /// Off.
    Off,
    /// On.
    On,
}

/// `--media-phase` (order as the catalogue's choices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MediaPhaseArg {
    /// Henyey–Greenstein with the medium's g.
    Medium,
    /// Rayleigh.
    Rayleigh,
}

/// `--taa-weights` (order as the catalogue's choices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TaaWeightsArg {
    /// c / (1 + luma) (Karis's, the seed's).
    Luma,
    /// The radiance itself.
    Linear,
}

/// kiln-play renders .kiln files with Vulkan 1.3: in a window, headless to PNG or EXR, or as a
/// benchmark.
#[derive(Debug, Parser)]
#[command(name = "kiln-play", version, about, after_help = AFTER_HELP, args_override_self = true)]
pub struct Args {
    /// The .kiln file to play (`kiln compile` or `kiln demo` make one).
    pub file: Option<PathBuf>,
    /// Render without a window (no display server needed).
    #[arg(long)]
    pub headless: bool,
    /// Image size; the window's initial size.
    #[arg(long, value_name = "WxH", default_value = "1280x720")]
    pub size: Size,
    /// Frames to render headless (the last is written; default 1), to measure with --bench
    /// (default 100), or to show before closing the window (default: until closed).
    #[arg(long, value_name = "N")]
    pub frames: Option<u32>,
    /// Headless output: .png (tone-mapped sRGB) or .exr (linear radiance).
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Measure per-pass GPU times and the load breakdown (headless).
    #[arg(long, conflicts_with = "output")]
    pub bench: bool,
    /// Measure the compute traversal's throughput (Mrays/s) on primary, shadow and diffuse
    /// rays at --size from the file's camera, each set traced --frames times (default 20).
    #[arg(long, conflicts_with_all = ["bench", "reference", "output"])]
    pub bench_rays: bool,
    /// With --bench or --bench-rays: print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// With --bench: frames rendered before measuring.
    #[arg(long, value_name = "N", default_value_t = 10)]
    pub warmup: u32,
    /// Enable the Khronos validation layer; errors make the exit code 5.
    #[arg(long)]
    pub validate: bool,
    /// Use the first device whose name contains NAME (see --list-devices); default: a discrete
    /// GPU, else any, lavapipe last.
    #[arg(long, value_name = "NAME")]
    pub device: Option<String>,
    /// List the Vulkan devices and exit.
    #[arg(long)]
    pub list_devices: bool,
    /// Camera override: position, target and optionally the vertical field of view in degrees.
    #[arg(long, value_name = "PX,PY,PZ,TX,TY,TZ[,VFOV]", allow_hyphen_values = true)]
    pub camera: Option<CameraOverride>,
    /// With -o, --headless or --bench: move the camera through the poses of FILE over the
    /// frames (one `px,py,pz,tx,ty,tz[,vfov]` per line, `#` comments; frame i at i/(N−1) of
    /// the way, linear between poses): a fly-through, for timing and error with a moving camera.
    #[arg(long, value_name = "FILE", conflicts_with = "camera")]
    pub camera_path: Option<PathBuf>,
    /// Exposure in stops (radiance × 2^EV before tone mapping; PNG and window only).
    #[arg(long, value_name = "EV", default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
    /// How the G-buffer is made.
    #[arg(long, value_parser = techniques(Effect::GBuffer), default_value = "raster")]
    pub gbuffer: String,
    /// Shadows technique.
    #[arg(long, value_parser = techniques(Effect::Shadows), default_value = "shadowmap")]
    pub shadows: String,
    /// Ambient occlusion technique.
    #[arg(long, value_parser = techniques(Effect::Ao), default_value = "none")]
    pub ao: String,
    /// With --ao rt, sao or gtao: the AO radius in scene units (rt: the ray length; sao, gtao:
    /// the samples' world radius; default: --ao-reach times the scene's diagonal).
    #[arg(long, value_name = "R")]
    pub ao_radius: Option<f32>,
    /// With --ao rt, sao or gtao: the AO radius as a fraction of the scene's bounding-box
    /// diagonal, when no --ao-radius is given (default: rt 0.1, ≥ 10 making every hit occlude
    /// fully, the sky's true visibility; sao and gtao 0.05, about the seed's 1.8 m in Sponza).
    #[arg(long, value_name = "FRACTION")]
    pub ao_reach: Option<f32>,
    /// With --ao sao: samples per AO pixel on the spiral, 1 to 64 (default 16, the seed's N).
    #[arg(long, value_name = "N")]
    pub ao_samples: Option<u32>,
    /// With --ao sao: turns of the sample spiral, τ (default 7).
    #[arg(long, value_name = "TURNS")]
    pub ao_turns: Option<f32>,
    /// With --ao sao: resolution of the samples (default half, the seed's; the depth-aware blur
    /// upsamples).
    #[arg(long, value_enum, value_name = "RES")]
    pub ao_res: Option<AoResArg>,
    /// With --ao gtao: screen directions (slices) per pixel, 1 to 32 (default 3, XeGTAO's High).
    #[arg(long, value_name = "N")]
    pub ao_slices: Option<u32>,
    /// With --ao gtao: samples along each side of a slice, 1 to 64 (default 3, XeGTAO's High).
    #[arg(long, value_name = "N")]
    pub ao_steps: Option<u32>,
    /// Reflections technique.
    #[arg(long, value_parser = techniques(Effect::Reflections), default_value = "none")]
    pub reflections: String,
    /// With --reflections rt: resolution of the traced reflections.
    #[arg(long, value_enum, default_value = "full")]
    pub reflection_res: ReflectionResArg,
    /// With --reflections rt: surfaces rougher than this keep the split-sum ambient.
    #[arg(long, value_name = "ROUGHNESS", default_value_t = 1.0)]
    pub reflection_max_roughness: f32,
    /// With --reflections ssr: most iterations of the hierarchical march per pixel, 1 to 1024
    /// (default 48: each skips a cell of empty space a level up or refines a potential hit a
    /// level down; 48 crosses a 1080p screen with room to refine, fewer lose distant hits).
    #[arg(long, value_name = "N")]
    pub ssr_steps: Option<u32>,
    /// With --reflections ssr: surfaces rougher than this keep the split-sum ambient, 0 to 1
    /// (default 0.6: beyond it the reflection cone covers much of the screen, where one ray says
    /// little; faded over the last fifth below it).
    #[arg(long, value_name = "ROUGHNESS")]
    pub ssr_max_roughness: Option<f32>,
    /// With --shadows rt: sphere radius of point and spot lights in scene units (0: hard
    /// shadows, as the file's punctual lights imply).
    #[arg(long, value_name = "R", default_value_t = 0.0)]
    pub light_radius: f32,
    /// With --shadows rt: angular diameter of directional lights in degrees (the sun: 0.53).
    #[arg(long, value_name = "DEGREES", default_value_t = 0.0)]
    pub sun_angle: f32,
    /// With --shadows linespace: how a filled shaft is decided. ends: exact triangle tests in the
    /// cells holding the ray's ends, a filled shaft elsewhere occludes (conservative, cheapest);
    /// filled: exact tests wherever the shaft is filled (exact).
    #[arg(long, value_enum, default_value = "ends")]
    pub ls_shadow_test: LsShadowTestArg,
    /// Do not average the ray-traced passes over frames (every frame shows one sample): the
    /// same as --aa none.
    #[arg(long, conflicts_with = "aa")]
    pub no_accumulate: bool,
    /// What happens to samples across frames. accumulate: the ray-traced passes keep a running
    /// mean while the camera is still (a move restarts it); reproject: the mean follows the
    /// camera (reprojected, restarted only where a point was hidden); taa: that and temporal
    /// anti-aliasing (a sub-pixel jitter per frame, a reprojected, neighbourhood-clipped
    /// history); none: every frame its own.
    #[arg(long, value_parser = techniques(Effect::Aa), default_value = "accumulate")]
    pub aa: String,
    /// With --aa reproject: the longest history of the ray-traced passes while the camera
    /// moves, 1 to 1024 (default 32; a still camera's running mean is unbounded).
    #[arg(long, value_name = "N")]
    pub history_frames: Option<u32>,
    /// With --aa taa: the longest history in frames, 1 to 1024 (default 16): a new frame weighs
    /// at least 1/N; longer converges further on a still camera, smears more on a moving one.
    #[arg(long, value_name = "N")]
    pub taa_frames: Option<u32>,
    /// With --aa taa: how frames are blended (default luma: c / (1 + luma), the seed's,
    /// damping fireflies; linear: the radiance itself, converging to the supersampled image).
    #[arg(long, value_enum, value_name = "WEIGHTS")]
    pub taa_weights: Option<TaaWeightsArg>,
    /// Global illumination technique.
    #[arg(long, value_parser = techniques(Effect::Gi), default_value = "none")]
    pub gi: String,
    /// With --gi rt or linespace: bounces of indirect light after the visible surface, 1 to 8 (1: the sky,
    /// emissive surfaces and the light the first surface hit receives directly).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub gi_bounces: u32,
    /// With --gi linespace: what answers the bounce rays. pnmt: the shaft's stored hit, no
    /// triangle test (approximate); candidates: the shaft's triangle list (exact); preillum: the
    /// stored hit's baked radiance (one bounce, no shading).
    #[arg(long, value_enum, default_value = "pnmt")]
    pub gi_structure: GiStructureArg,
    /// With --gi ssgi: spiral samples per pixel on each level, 1 to 1024 (default 128, the
    /// seed's).
    #[arg(long, value_name = "N")]
    pub ssgi_samples: Option<u32>,
    /// With --gi ssgi: the finest level gathered (default half, the seed's ~540p at 1080p),
    /// upsampled to the screen with depth and normal weights.
    #[arg(long, value_enum, value_name = "RES")]
    pub ssgi_res: Option<MediaResArg>,
    /// With --gi ssgi: sample radius in pixels of each level, 4 to 256 (default 40, the seed's).
    #[arg(long, value_name = "PIXELS")]
    pub ssgi_radius: Option<u32>,
    /// With --gi ssgi: how the depth and normal pyramids are reduced (default voting, the
    /// seed's precise MIP mapping).
    #[arg(long, value_enum, value_name = "REDUCTION")]
    pub ssgi_mip: Option<SsgiMipArg>,
    /// With --gi ssgi: the seed's distance fall-off (1/r² → 1/r^2.5 beyond one scene unit) in
    /// place of visibility (default off).
    #[arg(long, value_enum, value_name = "ON")]
    pub ssgi_falloff: Option<OffOnArg>,
    /// With --gi ssgi: the most frames its running mean averages while the camera is still,
    /// 1 to 4096 (default 16).
    #[arg(long, value_name = "N")]
    pub ssgi_frames: Option<u32>,
    /// With --gi ssgi: how the sample spirals turn: pixel (a random angle per texel, the seed's)
    /// or tile (one per 8 × 8 texels, the default: coherent reads, 15 % faster on an H100, one
    /// frame's noise 14 % higher and correlated within a tile until frames average it).
    #[arg(long, value_enum, value_name = "HOW")]
    pub ssgi_rotation: Option<SsgiRotationArg>,
    /// Participating media technique.
    #[arg(long, value_parser = techniques(Effect::Media), default_value = "none")]
    pub media: String,
    /// With --media march: steps along the view ray through each medium, 1 to 1024.
    #[arg(long, value_name = "N", default_value_t = 32)]
    pub media_steps: u32,
    /// With --media mitchell or toth: samples per pixel, 1 to 1024 (default 60): mitchell's
    /// towards the light, toth's along the view ray (over an interleaving block).
    #[arg(long, value_name = "N")]
    pub media_samples: Option<u32>,
    /// With --media mitchell or sousa: resolution of the occlusion image or depth map and the
    /// first blurs, as a fraction of the screen's (default quarter).
    #[arg(long, value_enum, value_name = "RES")]
    pub media_res: Option<MediaResArg>,
    /// With --media mitchell: the shafts' gain where every sample sees the emitter (default
    /// 1.921, the seed's exposure 0.01921 × its 100 samples).
    #[arg(long, value_name = "GAIN")]
    pub media_exposure: Option<f32>,
    /// With --media sousa: samples per pass, TAPS (3 passes, steps 1/TAPS, 1/TAPS², 1/TAPS³ of
    /// the screen), 1 to 64 (default 6).
    #[arg(long, value_name = "N")]
    pub media_taps: Option<u32>,
    /// With --media sousa: the factor on each pass's sum at 6 taps (default 0.19, the seed's;
    /// scaled by 6/TAPS for other tap counts, so that taps refine rather than brighten).
    #[arg(long, value_name = "F")]
    pub media_brightness: Option<f32>,
    /// With --media toth: side of the interleaving block in pixels, 1 to 8 (default 4;
    /// block² must not exceed --media-samples).
    #[arg(long, value_name = "N")]
    pub media_block: Option<u32>,
    /// With --media toth: the phase function (default medium: Henyey–Greenstein with the
    /// medium's g, as the reference renders).
    #[arg(long, value_enum, value_name = "PHASE")]
    pub media_phase: Option<MediaPhaseArg>,
    /// Render the unbiased reference path tracer instead (headless, needs -o OUT.exr).
    #[arg(long, conflicts_with_all = ["bench", "bench_rays"])]
    pub reference: bool,
    /// With --reference: samples per pixel.
    #[arg(long, value_name = "N", default_value_t = 256)]
    pub spp: u32,
    /// Do not read or write the pipeline cache (~/.cache/kiln/pipelines.bin).
    #[arg(long)]
    pub no_pipeline_cache: bool,
    /// Wait for every pipeline before the first frame. By default, with ray-traced techniques
    /// (--shadows, --ao, --reflections or --gi rt or linespace), the first frames show a
    /// fallback whose pipelines compile in milliseconds (shadow maps for ray-traced shadows
    /// when the file has them, the split-sum ambient for reflections, no AO, the sky's ambient
    /// for GI) while the ray-traced pipelines compile in the background (seconds on a first
    /// run, without a driver or pipeline cache); frames switch when they are ready and a note
    /// says what was shown instead and for how long. Only the window shows fallback frames:
    /// headless output and every --bench frame come from the chosen techniques (--bench
    /// times the fallback's first frame and the chosen techniques' separately).
    #[arg(long)]
    pub no_progressive_pipelines: bool,
    /// Upload every texture level before the first frame. By default textures stream: the
    /// first frame samples only each texture's levels from the first at most 256 texels on a
    /// side down to 1x1 (a 2048x2048 texture's first part is 1/64 of its bytes), and the finer
    /// levels upload after it, coarse to fine, the frames switching to them once they are all
    /// resident. Only the window shows coarse frames: headless output and every --bench frame
    /// come from the refined textures (--bench times the first frame and the refinement
    /// separately).
    #[arg(long)]
    pub no_texture_streaming: bool,
}

impl Args {
    /// The value the command line gives a knob (flags named as the catalogue's knobs).
    fn knob(&self, name: &str) -> Option<KnobValue> {
        match name {
            "light-radius" => Some(KnobValue::Number(self.light_radius)),
            "sun-angle" => Some(KnobValue::Number(self.sun_angle)),
            "ls-shadow-test" => Some(KnobValue::Choice(self.ls_shadow_test as usize)),
            "ao-radius" => self.ao_radius.map(KnobValue::Number),
            "ao-reach" => self.ao_reach.map(KnobValue::Number),
            "ao-samples" => self.ao_samples.map(|n| KnobValue::Number(n as f32)),
            "ao-turns" => self.ao_turns.map(KnobValue::Number),
            "ao-res" => self.ao_res.map(|r| KnobValue::Choice(r as usize)),
            "ao-slices" => self.ao_slices.map(|n| KnobValue::Number(n as f32)),
            "ao-steps" => self.ao_steps.map(|n| KnobValue::Number(n as f32)),
            "reflection-res" => Some(KnobValue::Choice(self.reflection_res as usize)),
            "reflection-max-roughness" => Some(KnobValue::Number(self.reflection_max_roughness)),
            "ssr-steps" => self.ssr_steps.map(|n| KnobValue::Number(n as f32)),
            "ssr-max-roughness" => self.ssr_max_roughness.map(KnobValue::Number),
            "gi-bounces" => Some(KnobValue::Number(self.gi_bounces as f32)),
            "gi-structure" => Some(KnobValue::Choice(self.gi_structure as usize)),
            "ssgi-samples" => self.ssgi_samples.map(|n| KnobValue::Number(n as f32)),
            "ssgi-res" => self.ssgi_res.map(|r| KnobValue::Choice(r as usize)),
            "ssgi-radius" => self.ssgi_radius.map(|n| KnobValue::Number(n as f32)),
            "ssgi-mip" => self.ssgi_mip.map(|m| KnobValue::Choice(m as usize)),
            "ssgi-falloff" => self.ssgi_falloff.map(|f| KnobValue::Choice(f as usize)),
            "ssgi-frames" => self.ssgi_frames.map(|n| KnobValue::Number(n as f32)),
            "ssgi-rotation" => self.ssgi_rotation.map(|r| KnobValue::Choice(r as usize)),
            "media-steps" => Some(KnobValue::Number(self.media_steps as f32)),
            "media-samples" => self.media_samples.map(|n| KnobValue::Number(n as f32)),
            "media-res" => self.media_res.map(|r| KnobValue::Choice(r as usize)),
            "media-exposure" => self.media_exposure.map(KnobValue::Number),
            "media-taps" => self.media_taps.map(|n| KnobValue::Number(n as f32)),
            "media-brightness" => self.media_brightness.map(KnobValue::Number),
            "media-block" => self.media_block.map(|n| KnobValue::Number(n as f32)),
            "media-phase" => self.media_phase.map(|p| KnobValue::Choice(p as usize)),
            "taa-frames" => self.taa_frames.map(|n| KnobValue::Number(n as f32)),
            "history-frames" => self.history_frames.map(|n| KnobValue::Number(n as f32)),
            "taa-weights" => self.taa_weights.map(|w| KnobValue::Choice(w as usize)),
            _ => None,
        }
    }

    /// The techniques the flags choose, each with the knobs the command line sets.
    fn techniques(&self) -> PlayResult<Techniques> {
        let usage = |e: String| PlayError::new(Exit::Usage, e);
        // Every knob flag is checked, whether or not its technique was chosen.
        for info in catalogue() {
            for k in info.knobs {
                if let Some(v) = self.knob(k.name) {
                    k.check(v).map_err(|e| usage(format!("--{e}")))?;
                }
            }
        }
        let mut t = Techniques::default();
        let none = String::from("none");
        let chosen = [
            (Effect::GBuffer, &self.gbuffer),
            (Effect::Shadows, &self.shadows),
            (Effect::Ao, &self.ao),
            (Effect::Reflections, &self.reflections),
            (Effect::Gi, &self.gi),
            (Effect::Media, &self.media),
            (Effect::Aa, if self.no_accumulate { &none } else { &self.aa }),
        ];
        for (effect, name) in chosen {
            let knobs: Vec<(&str, KnobValue)> = techniques_of(effect)
                .find(|i| i.name == name.as_str())
                .map(|i| i.knobs.iter().filter_map(|k| self.knob(k.name).map(|v| (k.name, v))).collect())
                .unwrap_or_default();
            t.set(effect, name, &knobs).map_err(usage)?;
        }
        Ok(t)
    }

    fn session(&self, file: PathBuf) -> PlayResult<SessionOptions> {
        if !self.exposure.is_finite() {
            return Err(PlayError::new(Exit::Usage, "--exposure must be finite"));
        }
        if self.ao_radius == Some(0.0) {
            return Err(PlayError::new(Exit::Usage, "--ao-radius must be greater than 0"));
        }
        let techniques = self.techniques()?;
        Ok(SessionOptions {
            file,
            gpu: GpuOptions {
                validate: self.validate,
                device: self.device.clone(),
                surface_extensions: Vec::new(),
                pipeline_cache: if self.no_pipeline_cache { None } else { default_cache_path() },
                // Only the ray benchmark traces through the driver's pipeline.
                ray_tracing_pipeline: self.bench_rays,
                max_storage_buffer: None,
            },
            render: RenderSettings {
                techniques,
                exposure: self.exposure,
                purpose: if self.reference { Purpose::Reference } else { Purpose::Frames },
            },
            width: self.size.width,
            height: self.size.height,
            camera: self.camera,
            camera_path: self.camera_path.as_deref().map(CameraPath::load).transpose()?,
            readback: None,
            pipelines: if self.no_progressive_pipelines {
                PipelineStart::Complete
            } else {
                PipelineStart::Progressive
            },
            textures: if self.no_texture_streaming {
                TextureUpload::Whole
            } else {
                TextureUpload::CoarseFirst
            },
        })
    }
}

fn run_reference(args: &Args, options: &SessionOptions, start: Instant) -> PlayResult {
    let output =
        args.output.as_ref().ok_or_else(|| PlayError::new(Exit::Usage, "--reference needs -o OUT.exr"))?;
    if crate::image_out::OutputKind::of(output)? != crate::image_out::OutputKind::Exr {
        return Err(PlayError::new(Exit::Usage, "--reference writes linear radiance: give -o OUT.exr"));
    }
    let (report, rgb) = crate::reference::render(options, args.spp, start)?;
    if rgb.iter().any(|v| !v.is_finite()) {
        return Err(PlayError::new(Exit::Gpu, "the reference image holds NaN or infinite values"));
    }
    crate::reference::write_exr(output, report.width, report.height, &rgb, report.spp)?;
    eprintln!(
        "wrote {} ({}x{}, {} spp) in {:.1} s: {:.2} M samples/s on {}",
        output.display(),
        report.width,
        report.height,
        report.spp,
        report.seconds,
        report.samples_per_second * 1e-6,
        report.device
    );
    Ok(())
}

fn validation_verdict(errors: u32) -> PlayResult {
    if errors > 0 {
        return Err(PlayError::new(Exit::Gpu, format!("the validation layer reported {errors} error(s)")));
    }
    Ok(())
}

/// Runs the command line; `start` is the process start.
pub fn run(args: Args, start: Instant) -> PlayResult {
    if args.list_devices {
        for (name, kind, version) in list_devices()? {
            println!("{name}  ({kind}, Vulkan {version})");
        }
        return Ok(());
    }
    let Some(file) = args.file.clone() else {
        println!(
            "kiln-play {} (format {}.{}): give a .kiln file to play; --help explains",
            env!("CARGO_PKG_VERSION"),
            kiln_format::header::VERSION_MAJOR,
            kiln_format::header::VERSION_MINOR
        );
        return Ok(());
    };
    let options = args.session(file)?;
    if args.reference {
        return run_reference(&args, &options, start);
    }
    if args.json && !args.bench && !args.bench_rays {
        return Err(PlayError::new(Exit::Usage, "--json goes with --bench or --bench-rays"));
    }
    if args.bench_rays {
        let report = crate::raybench::run(&options, args.frames.unwrap_or(20), start)?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&report).unwrap_or_default());
        } else {
            print!("{}", report.table());
        }
        return Ok(());
    }
    if args.bench {
        let report = bench::run(&options, args.warmup, args.frames.unwrap_or(100), start)?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&report).unwrap_or_default());
        } else {
            print!("{}", report.table());
        }
        return validation_verdict(report.validation_errors);
    }
    if args.headless || args.output.is_some() {
        if args.output.is_none() {
            eprintln!("note: no -o given; rendering without writing an image");
        }
        let result = headless::run(&options, args.frames.unwrap_or(1), args.output.as_deref(), start)?;
        let s = &result.session;
        for w in &s.warnings {
            eprintln!("warning: {w}");
        }
        for n in &s.notes {
            eprintln!("note: {n}");
        }
        if let Some(out) = &args.output {
            // Behind a fallback, its first frame and the chosen techniques' are both timed.
            let chosen = if s.times.fallback.is_empty() {
                String::new()
            } else {
                format!(", {:.0} ms with the chosen techniques", s.times.full_frame_since_start_ms)
            };
            eprintln!(
                "wrote {} ({}x{}, {}) in {:.0} ms (first frame {:.0} ms after start{chosen}; device {})",
                out.display(),
                options.width,
                options.height,
                s.scene.manifest.scene_name,
                s.since_start_ms(),
                s.times.first_frame_since_start_ms,
                s.gpu.name
            );
        }
        if result.non_finite > 0 {
            return Err(PlayError::new(
                Exit::Gpu,
                format!("{} pixel(s) of the frame are NaN or infinite", result.non_finite),
            ));
        }
        return validation_verdict(s.validation_errors());
    }
    window::run(options, args.frames, start)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{Aa, Ao, GBuffer, Gi, ReflectionRes, Reflections, ScreenFraction, Shadows};

    fn parse(args: &[&str]) -> Result<Args, clap::Error> {
        Args::try_parse_from(std::iter::once("kiln-play").chain(args.iter().copied()))
    }

    fn techniques(args: &[&str]) -> Techniques {
        parse(args).unwrap().techniques().unwrap()
    }

    #[test]
    fn flags_set_technique_values_with_their_knobs() {
        let t = techniques(&[
            "f.kiln",
            "--gbuffer",
            "visibility",
            "--shadows",
            "rt",
            "--light-radius",
            "1",
            "--sun-angle",
            "0.53",
            "--ao",
            "rt",
            "--ao-radius",
            "0.5",
            "--reflections",
            "rt",
            "--reflection-res",
            "half",
            "--reflection-max-roughness",
            "0.4",
            "--gi",
            "rt",
            "--gi-bounces",
            "2",
            "--no-accumulate",
        ]);
        assert_eq!(t.gbuffer, GBuffer::Visibility);
        assert_eq!(t.shadows, Shadows::Rt { light_radius: 1.0, sun_degrees: 0.53 });
        assert_eq!(t.ao, Ao::Rt { radius: Some(0.5), reach: 0.1 });
        assert_eq!(t.reflections, Reflections::Rt { resolution: ReflectionRes::Half, max_roughness: 0.4 });
        assert_eq!(t.gi, Gi::Rt { bounces: 2 });
        assert_eq!(t.aa, Aa::None);
        let e = parse(&["f.kiln", "--gi", "rt", "--gi-bounces", "9"]).unwrap().techniques().unwrap_err();
        assert!(e.to_string().contains("gi-bounces"), "{e}");
        let d = techniques(&["f.kiln"]);
        assert_eq!(d, Techniques::default());
        assert_eq!(d.shadows, Shadows::ShadowMap);
    }

    #[test]
    fn aa_flags_choose_taa_with_its_knobs() {
        let t = techniques(&["f.kiln", "--aa", "taa", "--taa-frames", "8", "--taa-weights", "luma"]);
        assert_eq!(t.aa, Aa::Taa { frames: 8, luma_weights: true });
        assert_eq!(techniques(&["f.kiln", "--aa", "taa"]).aa, Aa::Taa { frames: 16, luma_weights: false });
        assert_eq!(techniques(&["f.kiln", "--aa", "none"]).aa, Aa::None);
        let t = techniques(&["f.kiln", "--aa", "reproject", "--history-frames", "8"]);
        assert_eq!(t.aa, Aa::Reproject { frames: 8 });
        assert_eq!(t.aa.reprojected(), Some(8));
        let e = parse(&["f.kiln", "--aa", "taa", "--taa-frames", "0"]).unwrap().techniques().unwrap_err();
        assert!(e.message.contains("--taa-frames"), "{}", e.message);
        let e = parse(&["f.kiln", "--aa", "taa", "--no-accumulate"]).unwrap_err().to_string();
        assert!(e.contains("--no-accumulate") && e.contains("--aa"), "{e}");
    }

    #[test]
    fn ssr_flags_set_its_knobs_with_their_defaults() {
        assert_eq!(
            techniques(&["f.kiln", "--reflections", "ssr"]).reflections,
            Reflections::Ssr { steps: 48, max_roughness: 0.6 }
        );
        let t = techniques(&[
            "f.kiln",
            "--reflections",
            "ssr",
            "--ssr-steps",
            "96",
            "--ssr-max-roughness",
            "0.3",
        ]);
        assert_eq!(t.reflections, Reflections::Ssr { steps: 96, max_roughness: 0.3 });
        for bad in [&["--ssr-steps", "0"][..], &["--ssr-max-roughness", "1.5"]] {
            let args: Vec<&str> =
                ["f.kiln", "--reflections", "ssr"].into_iter().chain(bad.iter().copied()).collect();
            let e = parse(&args).unwrap().techniques().unwrap_err();
            assert_eq!(e.exit, Exit::Usage);
            assert!(e.message.contains(bad[0]), "{bad:?}: {}", e.message);
        }
    }

    #[test]
    fn the_last_flag_wins() {
        assert_eq!(techniques(&["f.kiln", "--shadows", "rt", "--shadows", "none"]).shadows, Shadows::None);
        let t = techniques(&["f.kiln", "--ao", "rt", "--ao-radius", "2", "--ao-radius", "3"]);
        assert_eq!(t.ao, Ao::Rt { radius: Some(3.0), reach: 0.1 });
    }

    #[test]
    fn screen_space_ao_flags_set_their_knobs_with_the_techniques_defaults() {
        let sao = techniques(&["f.kiln", "--ao", "sao"]);
        assert_eq!(
            sao.ao,
            Ao::Sao { radius: None, reach: 0.05, samples: 16, turns: 7.0, resolution: ScreenFraction::Half }
        );
        let t = techniques(&[
            "f.kiln",
            "--ao",
            "sao",
            "--ao-radius",
            "1.8",
            "--ao-samples",
            "8",
            "--ao-turns",
            "5",
            "--ao-res",
            "full",
        ]);
        assert_eq!(
            t.ao,
            Ao::Sao {
                radius: Some(1.8),
                reach: 0.05,
                samples: 8,
                turns: 5.0,
                resolution: ScreenFraction::Full
            }
        );
        assert_eq!(
            techniques(&["f.kiln", "--ao", "gtao"]).ao,
            Ao::Gtao { radius: None, reach: 0.05, slices: 3, steps: 3 }
        );
        let t = techniques(&[
            "f.kiln",
            "--ao",
            "gtao",
            "--ao-slices",
            "9",
            "--ao-steps",
            "4",
            "--ao-reach",
            "0.2",
        ]);
        assert_eq!(t.ao, Ao::Gtao { radius: None, reach: 0.2, slices: 9, steps: 4 });
        // --ao-reach keeps each technique's own default when not given.
        assert_eq!(techniques(&["f.kiln", "--ao", "rt"]).ao, Ao::Rt { radius: None, reach: 0.1 });
        // Out of range, fractional or unknown values name the flag.
        for bad in [
            &["--ao", "sao", "--ao-samples", "0"][..],
            &["--ao", "sao", "--ao-samples", "65"],
            &["--ao", "gtao", "--ao-slices", "33"],
            &["--ao", "gtao", "--ao-steps", "0"],
            &["--ao", "sao", "--ao-turns=-1"],
            &["--ao", "sao", "--ao-reach", "0"],
        ] {
            let args: Vec<&str> = std::iter::once("f.kiln").chain(bad.iter().copied()).collect();
            let e = parse(&args).unwrap().techniques().unwrap_err();
            assert_eq!(e.exit, Exit::Usage);
            let flag = bad[2].split('=').next().unwrap();
            assert!(e.message.contains(flag), "{bad:?}: {}", e.message);
        }
        let e = parse(&["f.kiln", "--ao", "sao", "--ao-res", "quarter"]).unwrap_err().to_string();
        assert!(e.contains("full") && e.contains("half"), "{e}");
    }

    #[test]
    fn contradictory_modes_are_refused_naming_both_flags() {
        for (a, b) in
            [("--reference", "--bench"), ("--bench", "--bench-rays"), ("--reference", "--bench-rays")]
        {
            let e = parse(&["f.kiln", a, b]).unwrap_err().to_string();
            assert!(e.contains(a) && e.contains(b), "{a} {b}: {e}");
        }
        let e = parse(&["f.kiln", "--bench", "-o", "x.png"]).unwrap_err().to_string();
        assert!(e.contains("--bench") && e.contains("--output"), "{e}");
    }

    #[test]
    fn bad_values_are_usage_errors_naming_the_flag() {
        let e = parse(&["f.kiln", "--light-radius=-1"]).unwrap().techniques().unwrap_err();
        assert_eq!(e.exit, Exit::Usage);
        assert!(e.message.contains("--light-radius"), "{}", e.message);
        let e = parse(&["f.kiln", "--shadows", "raytraced"]).unwrap_err().to_string();
        assert!(e.contains("shadowmap") && e.contains("rt"), "{e}");
    }
}
