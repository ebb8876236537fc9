//! `kiln-bench`'s command line: raw arguments, checked, turned into [`SweepOptions`].

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::Parser;

use crate::camera::{CameraOverride, CameraPath};
use crate::cli::Size;
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::GpuOptions;
use crate::gpu::default_cache_path;
use crate::render::techniques::{KnobRole, catalogue};

use super::measure::Timing;
use super::plan::{Request, Target, preset_help};
use super::results::{self, Results};
use super::{PathSweep, SweepOptions, report};

/// Every technique as a point of (GPU time, error against a path-traced reference).
///
/// For each camera, kiln-bench path-traces a reference (two independent halves, whose
/// disagreement is the reference's noise floor; cached in --out), then renders every technique
/// of every chosen effect at every value of its quality knobs and every accumulated frame
/// count, each in a fresh session: the image is compared with the reference (mean HDR-FLIP,
/// relMSE, RMSE) and the frame timed on the GPU (median, p10, p90). Effect charts hold the other
/// effects fixed (raster G-buffer, shadow maps where the file has them, the rest off), so two
/// points differ by their effect alone; the "frame" chart compares whole-frame presets.
///
/// Writes OUT/results.json, results.csv, one SVG and PNG chart per effect (Pareto front drawn,
/// noise floor as a band) and index.html; prints a table (or the JSON with --json).
#[derive(Debug, Parser)]
#[command(name = "kiln-bench", version, after_help = EXIT_CODES)]
pub struct Args {
    /// The compiled scene (.kiln, with a BVH: the reference path tracer needs one).
    pub file: Option<PathBuf>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720")]
    pub size: Size,
    /// A camera instead of the file's: px,py,pz,tx,ty,tz[,vfov]. Repeat for several; each gets
    /// its own reference and charts.
    #[arg(long = "camera", allow_negative_numbers = true)]
    pub cameras: Vec<CameraOverride>,
    /// Charts to make, comma-separated: shadows, direct, ao, reflections, gi, denoise, media,
    /// aa, frame.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "shadows,direct,ao,reflections,gi,denoise,media,aa,frame"
    )]
    pub effects: Vec<String>,
    /// Only these techniques, comma-separated: EFFECT:TECHNIQUE (e.g. ao:rt, frame:rt-taa)
    /// or TECHNIQUE in any effect. Default: all (--list shows them).
    #[arg(long, value_delimiter = ',')]
    pub techniques: Vec<String>,
    /// Frame counts at which accumulating techniques are measured.
    #[arg(long, value_delimiter = ',', default_value = "1,4,16,64")]
    pub frames_accumulated: Vec<u32>,
    /// A moving camera: every configuration renders --path-frames frames along the poses of
    /// FILE (as kiln-play --camera-path reads it) and is measured at the last one, against the
    /// reference at the last pose (the accumulating passes restart while the camera moves;
    /// --aa taa carries a reprojected history).
    #[arg(long, value_name = "FILE", conflicts_with = "cameras")]
    pub camera_path: Option<PathBuf>,
    /// With --camera-path: the frames the path takes.
    #[arg(long, value_name = "N", default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=100000))]
    pub path_frames: u32,
    /// Reference samples per pixel (rendered as two halves of half each).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(2..))]
    pub reference_spp: u32,
    /// Frames timed per configuration (at least 100 for figures you quote).
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u32).range(1..))]
    pub timing_frames: u32,
    /// Frames rendered and dropped before timing.
    #[arg(long, default_value_t = 10)]
    pub warmup: u32,
    /// Output folder (results, charts, page, the reference cache).
    #[arg(long, short, default_value = "kiln-bench-out")]
    pub out: PathBuf,
    /// Print the results as JSON on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Compare with an earlier results.json: points slower at equal error or worse at equal
    /// time are marked, and the exit code is 6.
    #[arg(long, value_name = "OLD.json")]
    pub compare: Option<PathBuf>,
    /// Also write every measured image and the reference as EXR into OUT/images/, each measured
    /// image with its per-pixel HDR-FLIP as a heat-map PNG (`...-flip.png`).
    #[arg(long)]
    pub keep_images: bool,
    /// Compare two EXR images instead of sweeping: REFERENCE.exr IMAGE.exr. Prints the mean
    /// HDR-FLIP, relMSE and RMSE that kiln-bench measures and writes the per-pixel HDR-FLIP as a
    /// heat map to OUT/flip.png (black none, then red, yellow, white). Renders from
    /// `kiln-play --headless -o X.exr` and `kiln-play --reference -o X.exr` compare directly.
    #[arg(long, num_args = 2, value_names = ["REFERENCE.exr", "IMAGE.exr"], conflicts_with_all = ["file", "replot", "compare", "json"])]
    pub diff: Option<Vec<PathBuf>>,
    /// Measure every combination of every technique's quality knobs. By default each knob is
    /// varied alone around the defaults, then the combinations of the values the chart's Pareto
    /// front shows are measured (at most 8 more per technique): the default sweep stays minutes
    /// long however many knobs a technique has.
    #[arg(long)]
    pub exhaustive: bool,
    /// List the effects, techniques, knobs and presets, and exit.
    #[arg(long)]
    pub list: bool,
    /// Draw the charts, page and CSV of an earlier results.json into --out again (no GPU
    /// needed), e.g. after a kiln-bench update; with --compare, marks its regressions.
    #[arg(long, value_name = "RESULTS.json", conflicts_with_all = ["file", "json", "keep_images"])]
    pub replot: Option<PathBuf>,
    /// Use the first device whose name contains this.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Khronos validation layer (errors fail the configuration).
    #[arg(long)]
    pub validate: bool,
    /// No progress bar even on a terminal.
    #[arg(long, short)]
    pub quiet: bool,
}

const EXIT_CODES: &str = "Exit codes: 0 done; 1 bad input (a file without a BVH, a broken \
results file); 2 usage; 3 no Vulkan device; 4 I/O; 5 a configuration failed on the GPU or gave NaN \
or infinity (the others are still written); 6 --compare found a regression.";

impl Args {
    /// The sweep these arguments ask for.
    pub fn options(&self, file: PathBuf) -> PlayResult<SweepOptions> {
        let targets = self
            .effects
            .iter()
            .map(|e| Target::parse(e.trim()))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| PlayError::new(Exit::Usage, format!("--effects: {e}")))?;
        let mut frames = self.frames_accumulated.clone();
        frames.sort_unstable();
        frames.dedup();
        let request =
            Request { targets, techniques: self.techniques.clone(), frames, exhaustive: self.exhaustive };
        request.check().map_err(|e| PlayError::new(Exit::Usage, e))?;
        super::check_size(self.size.width, self.size.height)?;
        Ok(SweepOptions {
            file,
            width: self.size.width,
            height: self.size.height,
            cameras: self.cameras.iter().copied().map(Some).collect(),
            camera_path: match &self.camera_path {
                Some(file) => Some(PathSweep {
                    path: CameraPath::load(file)?,
                    frames: self.path_frames,
                    name: file.file_stem().map_or("path".into(), |s| s.to_string_lossy().into_owned()),
                }),
                None => None,
            },
            request,
            reference_spp: self.reference_spp,
            timing: Timing { warmup: self.warmup, frames: self.timing_frames },
            out: self.out.clone(),
            gpu: GpuOptions {
                validate: self.validate,
                device: self.device.clone(),
                surface_extensions: Vec::new(),
                pipeline_cache: default_cache_path(),
                ray_tracing_pipeline: false,
                max_storage_buffer: None,
            },
            keep_images: self.keep_images,
            progress: !self.quiet && std::io::stderr().is_terminal(),
        })
    }
}

/// An earlier results.json.
fn read_results(path: &std::path::Path) -> PlayResult<Results> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| PlayError::new(Exit::Io, format!("{}: {e}", path.display())))?;
    Results::from_json(&text, &path.display().to_string())
}

/// `--list`.
fn list() -> String {
    let mut s = String::from("effects and techniques (EFFECT:TECHNIQUE for --techniques):\n");
    for t in catalogue() {
        s.push_str(&format!("  {}:{}  {}\n", t.effect, t.name, t.help));
        for k in t.knobs {
            let role = match k.role {
                KnobRole::Quality => "swept",
                KnobRole::Scene => "held at its default: it sizes the lights the reference renders",
            };
            s.push_str(&format!("      --{}: {} ({role})\n", k.name, k.help));
        }
    }
    s.push_str("frame presets (frame:NAME; each with the default --direct restir where the file has emissive materials):\n");
    for p in preset_help() {
        s.push_str(&format!("  {p}\n"));
    }
    s
}

/// Runs the command line.
pub fn run(args: Args) -> PlayResult {
    if args.list {
        print!("{}", list());
        return Ok(());
    }
    if let Some(files) = &args.diff {
        super::report::create_dir(&args.out)?;
        return super::diff::run(&files[0], &files[1], &args.out.join("flip.png"));
    }
    // Read the old results first: a typo in the path should not cost a whole sweep.
    let old = args.compare.as_deref().map(read_results).transpose()?;
    let mut outcome = if let Some(path) = &args.replot {
        super::Outcome { results: read_results(path)?, failures: Vec::new() }
    } else {
        let Some(file) = args.file.clone() else {
            return Err(PlayError::new(Exit::Usage, "give a .kiln file to benchmark (--help explains)"));
        };
        super::run(&args.options(file)?)?
    };
    let mut regressions = 0;
    if let Some(old) = &old {
        for note in results::compare(&mut outcome.results, old) {
            eprintln!("note: {note}");
        }
        regressions = outcome.results.points.iter().filter(|p| p.regression.is_some()).count();
    }
    let written = report::write(&outcome.results, &args.out)?;
    for w in &outcome.results.warnings {
        eprintln!("warning: {w}");
    }
    if args.json {
        println!("{}", outcome.results.to_json());
    } else {
        print!("{}", report::text(&outcome.results));
        println!("wrote {} files to {} (open index.html)", written.len(), args.out.display());
    }
    if !outcome.failures.is_empty() {
        let lines: Vec<String> =
            outcome.failures.iter().map(|f| format!("{} {}: {}", f.effect, f.technique, f.reason)).collect();
        return Err(PlayError::new(Exit::Gpu, format!("configurations failed:\n  {}", lines.join("\n  "))));
    }
    if regressions > 0 {
        return Err(PlayError::new(
            Exit::Regression,
            format!("{regressions} point(s) regressed against the old run"),
        ));
    }
    Ok(())
}
