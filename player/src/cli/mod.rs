//! Command line of `kiln-play`.

use std::path::PathBuf;

use clap::{Arg, Command, CommandFactory, FromArgMatches, Parser};

use crate::camera::{CameraOverride, CameraPath};
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{GpuOptions, default_cache_path};
use crate::render::Effect;
use crate::render::presets::{self, Preset};
use crate::render::techniques::{KnobValue, Techniques};
use crate::render::{Purpose, RenderSettings};
use crate::scene::TextureUpload;
use crate::session::{PipelineStart, SessionOptions};
use crate::sweep::budget::{self, Measurements};

mod run;
mod technique_flags;
pub use run::run;
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
    /// with `probes` (about 1 ms on the H200 with the default visibility G-buffer: the McGuire
    /// box 0.082 HDR-FLIP against 0.342 for the screen-space `baked`; pica_pica 0.0444 against
    /// `baked` 0.0583 and `hybrid` 0.0573; `probes-rt` adds ray-traced shadows: 0.0423 at
    /// 1.33 ms; `probes-rt-refl` ray-traced reflections too: 0.0378 after 16 still frames at
    /// 1.72 ms, against `probes-rt`'s 0.0426).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::techniques::ao::{self, Radius};
    use crate::render::techniques::reflections::rt::ReflectionRes;
    use crate::render::techniques::{Effect, catalogue};
    use crate::render::techniques::{aa, gi, reflections, shadows};
    use crate::render::{Aa, Ao, GBuffer, Gi, Reflections, ScreenFraction, Shadows};

    fn parse(args: &[&str]) -> Result<Args, clap::Error> {
        match parse_from(std::iter::once("kiln-play").chain(args.iter().copied()))? {
            Invocation::Play(a) => Ok(*a),
            other => panic!("{args:?} is not a session: {other:?}"),
        }
    }

    fn techniques(args: &[&str]) -> Techniques {
        parse(args).unwrap().techniques(std::path::Path::new("missing.kiln")).unwrap()
    }

    /// The message of a refused command line, whether clap or the techniques refuse it; usage
    /// errors either way.
    fn refusal(args: &[&str]) -> String {
        match parse(args) {
            Err(e) => {
                assert_eq!(e.exit_code(), 2, "{args:?}: {e}");
                e.to_string()
            }
            Ok(a) => {
                let e = a.techniques(std::path::Path::new("missing.kiln")).expect_err("refused");
                assert_eq!(e.exit, Exit::Usage);
                e.message
            }
        }
    }

    const AO_RT: Ao = Ao::Rt(ao::rt::Rt { radius: Radius { radius: None, reach: 0.1 } });

    #[test]
    fn flags_set_technique_values_with_their_knobs() {
        let t = techniques(&[
            "f.kiln",
            "--gbuffer",
            "raster",
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
        assert_eq!(t.gbuffer, GBuffer::Raster(crate::render::techniques::gbuffer::raster::Raster));
        assert_eq!(t.shadows, Shadows::Rt(shadows::rt::Rt { light_radius: 1.0, sun_degrees: 0.53 }));
        assert_eq!(t.ao, Ao::Rt(ao::rt::Rt { radius: Radius { radius: Some(0.5), reach: 0.1 } }));
        assert_eq!(
            t.reflections,
            Reflections::Rt(reflections::rt::Rt {
                resolution: ReflectionRes::Half,
                max_roughness: 0.4,
                metal_bounce: reflections::rt::METAL_BOUNCE
            })
        );
        assert_eq!(t.gi, Gi::Rt(gi::rt::Rt { bounces: 2, regularize: 0.5 }));
        assert_eq!(t.aa, Aa::Off(aa::none::Off));
        let e = refusal(&["f.kiln", "--gi", "rt", "--gi-bounces", "9"]);
        assert!(e.contains("gi-bounces"), "{e}");
        let d = techniques(&["f.kiln"]);
        assert_eq!(d, Techniques::default());
        assert_eq!(d.name_of(Effect::Shadows), "shadowmap");
    }

    #[test]
    fn aa_flags_choose_taa_with_its_knobs() {
        let t = techniques(&["f.kiln", "--aa", "taa", "--taa-frames", "8", "--taa-weights", "luma"]);
        assert_eq!(t.aa, Aa::Taa(aa::taa::Taa { frames: 8, luma_weights: true }));
        assert_eq!(
            techniques(&["f.kiln", "--aa", "taa"]).aa,
            Aa::Taa(aa::taa::Taa { frames: 16, luma_weights: false })
        );
        assert_eq!(techniques(&["f.kiln", "--aa", "none"]).aa, Aa::Off(aa::none::Off));
        let t = techniques(&["f.kiln", "--aa", "reproject", "--history-frames", "8"]);
        assert_eq!(t.aa, Aa::Reproject(aa::reproject::Reproject { frames: 8 }));
        assert_eq!(t.aa.reprojected(), Some(8));
        let e = refusal(&["f.kiln", "--aa", "taa", "--taa-frames", "0"]);
        assert!(e.contains("--taa-frames"), "{e}");
        let e = parse(&["f.kiln", "--aa", "taa", "--no-accumulate"]).unwrap_err().to_string();
        assert!(e.contains("--no-accumulate") && e.contains("--aa"), "{e}");
    }

    #[test]
    fn ssr_flags_set_its_knobs_with_their_defaults() {
        assert_eq!(
            techniques(&["f.kiln", "--reflections", "ssr"]).reflections,
            Reflections::Ssr(reflections::ssr::Ssr { steps: 48, max_roughness: 0.6 })
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
        assert_eq!(t.reflections, Reflections::Ssr(reflections::ssr::Ssr { steps: 96, max_roughness: 0.3 }));
        for bad in [&["--ssr-steps", "0"][..], &["--ssr-max-roughness", "1.5"], &["--ssr-steps", "1.5"]] {
            let args: Vec<&str> =
                ["f.kiln", "--reflections", "ssr"].into_iter().chain(bad.iter().copied()).collect();
            let e = refusal(&args);
            assert!(e.contains(bad[0]), "{bad:?}: {e}");
        }
    }

    #[test]
    fn the_last_flag_wins() {
        assert_eq!(
            techniques(&["f.kiln", "--shadows", "rt", "--shadows", "none"]).name_of(Effect::Shadows),
            "none"
        );
        let t = techniques(&["f.kiln", "--ao", "rt", "--ao-radius", "2", "--ao-radius", "3"]);
        assert_eq!(t.ao, Ao::Rt(ao::rt::Rt { radius: Radius { radius: Some(3.0), reach: 0.1 } }));
    }

    #[test]
    fn screen_space_ao_flags_set_their_knobs_with_the_techniques_defaults() {
        let sao = techniques(&["f.kiln", "--ao", "sao"]);
        let sao_default = ao::sao::Sao {
            radius: Radius { radius: None, reach: 0.05 },
            samples: 16,
            turns: 7.0,
            resolution: ScreenFraction::Half,
        };
        assert_eq!(sao.ao, Ao::Sao(sao_default));
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
            Ao::Sao(ao::sao::Sao {
                radius: Radius { radius: Some(1.8), reach: 0.05 },
                samples: 8,
                turns: 5.0,
                resolution: ScreenFraction::Full
            })
        );
        let gtao = |reach, slices, steps| {
            Ao::Gtao(ao::gtao::Gtao { radius: Radius { radius: None, reach }, slices, steps })
        };
        assert_eq!(techniques(&["f.kiln", "--ao", "gtao"]).ao, gtao(0.05, 3, 3));
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
        assert_eq!(t.ao, gtao(0.2, 9, 4));
        // --ao-reach keeps each technique's own default when not given.
        assert_eq!(techniques(&["f.kiln", "--ao", "rt"]).ao, AO_RT);
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
            let e = refusal(&args);
            let flag = bad[2].split('=').next().unwrap();
            assert!(e.contains(flag), "{bad:?}: {e}");
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
        // A knob is checked whether or not its technique is chosen.
        let e = refusal(&["f.kiln", "--light-radius=-1"]);
        assert!(e.contains("--light-radius"), "{e}");
        let e = parse(&["f.kiln", "--shadows", "raytraced"]).unwrap_err().to_string();
        assert!(e.contains("shadowmap") && e.contains("rt"), "{e}");
    }

    /// The long help states each knob's default as the catalogue has it (the flags used to
    /// repeat the defaults by hand and disagreed: `--taa-weights` said luma, the catalogue
    /// linear), and each effect's default technique.
    #[test]
    fn help_states_the_catalogues_defaults() {
        let help = command().render_long_help().to_string();
        // Undo clap's wrapping: one flag's text per block (a flag's line is indented less than
        // its description's).
        let mut blocks: Vec<String> = Vec::new();
        for line in help.lines() {
            let indent = line.len() - line.trim_start().len();
            if line.trim_start().starts_with('-') && indent < 8 {
                blocks.push(line.trim().to_string());
            } else if let Some(b) = blocks.last_mut() {
                b.push(' ');
                b.push_str(line.trim());
            }
        }
        let flat = blocks.join(" ");
        for info in catalogue() {
            for k in info.knobs {
                let start = format!("--{} <", k.name);
                let block = blocks
                    .iter()
                    .find(|b| b.starts_with(&start))
                    .unwrap_or_else(|| panic!("--{} missing", k.name));
                let default = k.default_text();
                assert!(
                    block.contains(&format!("[default: {default}]"))
                        || block.contains(&format!("{} {default}", info.name)),
                    "--{} of {} {}: default {default} not in: {block}",
                    k.name,
                    info.effect,
                    info.name
                );
            }
        }
        assert!(flat.contains("--taa-weights <luma|linear>"), "{flat}");
        for e in Effect::ALL {
            assert!(help.contains(e.title()), "heading {e}");
            let default = Techniques::default().name_of(e);
            assert!(flat.contains(&format!("technique [default: {default}]")), "{e}");
        }
        // The short help names the effects and leaves the knobs to --help.
        let short = command().render_help().to_string();
        assert!(short.contains("--ao <TECHNIQUE>") && !short.contains("--ao-samples <N>"), "{short}");
        assert!(short.contains("kiln-play --help"), "{short}");
    }

    /// Completions and the man page name every flag the catalogue makes.
    #[test]
    fn completions_and_man_page_cover_the_catalogue() {
        let mut bash = Vec::new();
        write_generated(&Invocation::Completions(clap_complete::Shell::Bash), &mut bash).unwrap();
        let mut man = Vec::new();
        write_generated(&Invocation::Man, &mut man).unwrap();
        let (bash, man) = (String::from_utf8(bash).unwrap(), String::from_utf8(man).unwrap());
        for info in catalogue() {
            for k in info.knobs {
                assert!(bash.contains(&format!("--{}", k.name)), "bash: --{}", k.name);
                // roff escapes '-' as '\-'.
                assert!(man.contains(&format!("\\-\\-{}", k.name.replace('-', "\\-"))), "man: --{}", k.name);
            }
        }
        assert!(matches!(parse_from(["kiln-play", "completions", "zsh"]), Ok(Invocation::Completions(_))));
        assert!(matches!(parse_from(["kiln-play", "man"]), Ok(Invocation::Man)));
        assert!(parse_from(["kiln-play", "completions", "cmd.exe"]).is_err());
    }

    /// Every `kiln-play` line in the README and the docs parses and chooses valid techniques
    /// (a flag renamed or dropped breaks a documented command line).
    #[test]
    fn documented_command_lines_parse() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut files = vec![root.join("README.md")];
        if let Ok(dir) = std::fs::read_dir(root.join("docs")) {
            files.extend(
                dir.filter_map(|e| e.ok())
                    .map(|e| e.path())
                    .filter(|p| p.extension().is_some_and(|x| x == "md")),
            );
        }
        let mut checked = 0;
        for file in files {
            let text = std::fs::read_to_string(&file).unwrap();
            // Join continued lines, then take each command from `kiln-play` to a comment, a
            // pipe or the end of its code span.
            let text = text.replace("\\\n", " ");
            for line in text.lines() {
                let Some(at) = line.find("kiln-play ") else { continue };
                let rest = &line[at + "kiln-play ".len()..];
                let end = rest.find(['#', '`', '|', ';', '&', '>', ')']).unwrap_or(rest.len());
                let words: Vec<&str> = rest[..end].split_whitespace().collect();
                // Prose ("kiln-play renders ...") and placeholders ("kiln-play FILE [OPTIONS]").
                let runs = words.iter().any(|w| w.ends_with(".kiln"));
                if !runs || line.contains("...") || rest[..end].contains('[') {
                    continue;
                }
                let mut args = vec!["kiln-play"];
                args.extend(words.iter().copied());
                let parsed = parse_from(args.iter().copied());
                match parsed {
                    Ok(Invocation::Play(a)) => {
                        a.techniques(std::path::Path::new("missing.kiln"))
                            .unwrap_or_else(|e| panic!("{}: {line}: {e}", file.display()));
                    }
                    Ok(_) => {}
                    Err(e) => panic!("{}: `{}` is refused: {e}", file.display(), args.join(" ")),
                }
                checked += 1;
            }
        }
        assert!(checked >= 10, "only {checked} documented command lines found");
    }

    /// `--preset` sets its techniques and knobs; flags beside it override a technique or a knob
    /// and keep the rest of the preset.
    #[test]
    fn a_preset_sets_techniques_and_flags_override_it() {
        let t = techniques(&["f.kiln", "--preset", "rt-2"]);
        assert_eq!(t.gi, Gi::Rt(gi::rt::Rt { bounces: 2, regularize: 0.5 }));
        assert_eq!((t.name_of(Effect::Shadows), t.name_of(Effect::Denoise)), ("rt", "svgf"));
        let t = techniques(&["f.kiln", "--preset", "rt-2", "--gi-bounces", "3", "--denoise", "none"]);
        assert_eq!(t.gi, Gi::Rt(gi::rt::Rt { bounces: 3, regularize: 0.5 }));
        assert_eq!((t.name_of(Effect::Shadows), t.name_of(Effect::Denoise)), ("rt", "none"));
        let t = techniques(&["f.kiln", "--preset", "rt-4-taa", "--gi", "ssgi", "--no-accumulate"]);
        assert_eq!((t.name_of(Effect::Gi), t.name_of(Effect::Aa)), ("ssgi", "none"));
        assert!(refusal(&["f.kiln", "--preset", "fast"]).contains("rt-taa"));
    }

    /// A budget that is not a positive number of milliseconds is refused with the reason.
    #[test]
    fn a_budget_must_be_positive_milliseconds() {
        for bad in ["-2", "0", "nan", "inf"] {
            assert!(
                refusal(&["f.kiln", "--budget-ms", bad]).contains("positive number of milliseconds"),
                "{bad}"
            );
        }
    }
}
