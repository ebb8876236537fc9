//! Command line of `kiln-play`.

use std::path::PathBuf;
use std::time::Instant;

use clap::{Arg, Command, CommandFactory, FromArgMatches, Parser};

use crate::bench;
use crate::camera::{CameraOverride, CameraPath};
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{GpuOptions, default_cache_path, list_devices};
use crate::headless;
use crate::render::Effect;
use crate::render::presets::{self, Preset};
use crate::render::techniques::{KnobValue, Techniques};
use crate::render::{Purpose, RenderSettings};
use crate::scene::TextureUpload;
use crate::session::{PipelineStart, SessionOptions};
use crate::sweep::budget::{self, Measurements};
use crate::window;

mod technique_flags;
pub use technique_flags::TechniqueFlags;

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
(with --validate).

Shell completions and a man page: kiln-play completions SHELL, kiln-play man.";

const SHORT_AFTER_HELP: &str = "\
Each effect's flag picks its technique; the techniques' knobs (--ao-samples, --gi-bounces, ...),
every option and examples: kiln-play --help.";

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

/// kiln-play renders .kiln files with Vulkan 1.3: in a window, headless to PNG or EXR, or as a
/// benchmark.
#[derive(Debug, Parser)]
#[command(
    name = "kiln-play",
    version,
    about,
    after_help = SHORT_AFTER_HELP,
    after_long_help = AFTER_HELP,
    args_override_self = true
)]
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
    /// A named technique set for the whole frame (each carries indirect light; those that
    /// trace GI rays denoise it; `baked`, `baked-taa` and `probes` trace no rays). Technique and
    /// knob flags given beside it override its choices; `kiln-bench --list` says what each sets.
    /// Without --preset, --budget-ms and --gi, a file compiled with irradiance probes renders
    /// with `probes` (under 1 ms on the H200: the McGuire box 0.082 HDR-FLIP against 0.342
    /// for the screen-space `baked`; pica_pica 0.0473 against `baked` 0.0587 and `hybrid` 0.0577;
    /// `probes-rt` adds ray-traced shadows: 0.0453 at 1.29 ms).
    #[arg(long, value_name = "NAME", value_parser = clap::builder::PossibleValuesParser::new(crate::render::presets::PRESETS.map(|p| p.name)))]
    pub preset: Option<String>,
    /// Choose the whole frame by a GPU budget: of the frame presets measured (by
    /// --bench-results, else by the table built in from pica_pica on an H200), the one with the
    /// lowest error whose frame fits X ms (times scaled by the pixel count to --size); prints
    /// what it chose and why, and refuses (exit 2) when none fits. Technique and knob flags
    /// beside it override its choice.
    #[arg(long, value_name = "X", conflicts_with = "preset", allow_negative_numbers = true)]
    pub budget_ms: Option<f64>,
    /// With --budget-ms: the scene's own kiln-bench results.json (its frame chart).
    #[arg(long, value_name = "RESULTS.json", requires = "budget_ms")]
    pub bench_results: Option<PathBuf>,
    /// Headless output: .png (tone-mapped sRGB) or .exr (linear radiance).
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Measure per-pass GPU times and the load breakdown (headless).
    #[arg(long, conflicts_with = "output", help_heading = "Measuring")]
    pub bench: bool,
    /// Measure the compute traversal's throughput (Mrays/s) on primary, shadow and diffuse
    /// rays at --size from the file's camera, each set traced --frames times (default 20).
    #[arg(long, conflicts_with_all = ["bench", "reference", "output"], help_heading = "Measuring")]
    pub bench_rays: bool,
    /// With --bench or --bench-rays: print JSON instead of a table.
    #[arg(long, help_heading = "Measuring")]
    pub json: bool,
    /// With --bench: frames rendered before measuring.
    #[arg(long, value_name = "N", default_value_t = 10, help_heading = "Measuring", hide_short_help = true)]
    pub warmup: u32,
    /// Enable the Khronos validation layer; errors make the exit code 5.
    #[arg(long, help_heading = "Device and loading", hide_short_help = true)]
    pub validate: bool,
    /// Use the first device whose name contains NAME (see --list-devices); default: a discrete
    /// GPU, else any, lavapipe last.
    #[arg(long, value_name = "NAME", help_heading = "Device and loading")]
    pub device: Option<String>,
    /// List the Vulkan devices and exit.
    #[arg(long, help_heading = "Device and loading")]
    pub list_devices: bool,
    /// Camera override: position, target and optionally the vertical field of view in degrees,
    /// in world coordinates as the asset gives them (a file stored relative to an origin far
    /// from the world's, `kiln inspect` says which, is entered in world coordinates all the same).
    #[arg(long, value_name = "PX,PY,PZ,TX,TY,TZ[,VFOV]", allow_hyphen_values = true)]
    pub camera: Option<CameraOverride>,
    /// With -o, --headless or --bench: move the camera through the poses of FILE over the
    /// frames (one `px,py,pz,tx,ty,tz[,vfov]` per line, `#` comments; frame i at i/(N−1) of
    /// the way, linear between poses): a fly-through, for timing and error with a moving camera.
    #[arg(long, value_name = "FILE", conflicts_with = "camera", hide_short_help = true)]
    pub camera_path: Option<PathBuf>,
    /// Exposure in stops (radiance × 2^EV before tone mapping; PNG and window only).
    #[arg(long, value_name = "EV", default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
    /// Render the unbiased reference path tracer instead (headless, needs -o OUT.exr).
    #[arg(long, conflicts_with_all = ["bench", "bench_rays"], help_heading = "Measuring")]
    pub reference: bool,
    /// With --reference: samples per pixel.
    #[arg(long, value_name = "N", default_value_t = 256, help_heading = "Measuring")]
    pub spp: u32,
    /// Do not read or write the pipeline cache (~/.cache/kiln/pipelines.bin).
    #[arg(long, help_heading = "Device and loading", hide_short_help = true)]
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
    #[arg(long, help_heading = "Device and loading", hide_short_help = true)]
    pub no_progressive_pipelines: bool,
    /// Upload every texture level before the first frame. By default textures stream: the
    /// first frame samples only each texture's levels from the first at most 256 texels on a
    /// side down to 1x1 (a 2048x2048 texture's first part is 1/64 of its bytes), and the finer
    /// levels upload after it, coarse to fine, the frames switching to them once they are all
    /// resident. Only the window shows coarse frames: headless output and every --bench frame
    /// come from the refined textures (--bench times the first frame and the refinement
    /// separately).
    #[arg(long, help_heading = "Device and loading", hide_short_help = true)]
    pub no_texture_streaming: bool,
    /// The techniques and knobs the command line chooses (flags made from the catalogue by
    /// [`command`]).
    #[arg(skip)]
    pub choices: TechniqueFlags,
}

impl Args {
    /// The techniques the flags choose for `file`, each with the knobs the command line sets.
    pub fn techniques(&self, file: &std::path::Path) -> PlayResult<Techniques> {
        let usage = |e: String| PlayError::new(Exit::Usage, e);
        // Opened once for what the file's contents decide here; an unreadable file has no probes
        // (the session reports it).
        let opened = crate::session::open_file(file).ok();
        let probes = opened.as_ref().is_some_and(presets::has_probes);
        let mut preset = self.preset.as_deref().map(Preset::named).transpose().map_err(usage)?;
        if preset.is_none() && self.budget_ms.is_none() && !self.reference {
            preset = presets::default_for(probes, self.choices.given(Effect::Gi));
        }
        let mut gbuffer = None;
        if let Some(budget) = self.budget_ms {
            if !(budget > 0.0 && budget.is_finite()) {
                return Err(usage(format!(
                    "--budget-ms must be a positive number of milliseconds, not {budget}"
                )));
            }
            let measured = match &self.bench_results {
                Some(path) => Measurements::read(path)?,
                None => Measurements::built_in(probes),
            };
            let chosen = budget::choose(&measured, budget, self.size.width, self.size.height)?;
            eprintln!("{}", chosen.why);
            preset = Some(chosen.point.preset);
            gbuffer = Some(chosen.point.gbuffer.clone());
        }
        let mut t = self.choices.techniques(preset, gbuffer.as_deref()).map_err(usage)?;
        if self.choices.given(Effect::Direct).is_none()
            && !self.reference
            && t.name_of(Effect::Gi) == "probes"
            && t.name_of(Effect::Direct) != "none"
            && let Some(share) = opened.as_ref().and_then(presets::dim_emitters)
        {
            eprintln!(
                "note: the emissive surfaces' direct light comes from the probes (--direct none): it is at most \
                 {:.2} % of the light any probe sees (under {} %); --direct restir computes it per pixel",
                share * 100.0,
                presets::DIM_EMITTERS * 100.0
            );
            t.set(Effect::Direct, "none", &[]).map_err(usage)?;
        }
        Ok(t)
    }

    fn session(&self, file: PathBuf) -> PlayResult<SessionOptions> {
        if !self.exposure.is_finite() {
            return Err(PlayError::new(Exit::Usage, "--exposure must be finite"));
        }
        if self.choices.knob("ao-radius") == Some(KnobValue::Number(0.0)) {
            return Err(PlayError::new(Exit::Usage, "--ao-radius must be greater than 0"));
        }
        let techniques = self.techniques(&file)?;
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

/// `kiln-play`'s command line: the fixed flags of [`Args`] and, under a heading per effect,
/// each effect's technique flag and its techniques' knob flags, made from the catalogue
/// ([`crate::render::techniques::catalogue`]); `completions` and `man` write the shell
/// completions and the man page.
pub fn command() -> Command {
    let cmd = technique_flags::add(Args::command());
    let shell = Arg::new("shell")
        .required(true)
        .value_parser(clap::value_parser!(clap_complete::Shell))
        .help("bash, elvish, fish, powershell or zsh");
    cmd.subcommand(Command::new("completions").about("Write shell completions to stdout").arg(shell))
        .subcommand(Command::new("man").about("Write the man page (roff) to stdout"))
        .args_conflicts_with_subcommands(true)
}

/// What the command line asks for: a session, or completions or the man page.
#[derive(Debug)]
pub enum Invocation {
    /// Play, render or measure a file.
    Play(Box<Args>),
    /// Shell completions for a shell.
    Completions(clap_complete::Shell),
    /// The man page.
    Man,
}

/// Parses a command line (the program's name first), exiting with clap's message and exit code
/// 2 on a usage error (0 for --help and --version).
pub fn parse_from<I, T>(args: I) -> Result<Invocation, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let matches = command().try_get_matches_from(args)?;
    match matches.subcommand() {
        Some(("completions", m)) => {
            Ok(Invocation::Completions(*m.get_one::<clap_complete::Shell>("shell").expect("required")))
        }
        Some(("man", _)) => Ok(Invocation::Man),
        _ => {
            let mut args = Args::from_arg_matches(&matches)?;
            args.choices = TechniqueFlags::from_matches(&matches);
            Ok(Invocation::Play(Box::new(args)))
        }
    }
}

/// Writes what `invocation` asks for beyond a session (completions, the man page) to `out`.
pub fn write_generated(invocation: &Invocation, out: &mut dyn std::io::Write) -> std::io::Result<()> {
    let mut cmd = command();
    match invocation {
        Invocation::Completions(shell) => {
            clap_complete::generate(*shell, &mut cmd, "kiln-play", out);
            Ok(())
        }
        Invocation::Man => clap_mangen::Man::new(cmd).render(out),
        Invocation::Play(_) => Ok(()),
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
mod tests;
