//! The compile pipeline shared by `compile`, `plan` and `demo`: load → validate → plan → bake →
//! write, with the report and the depfile.

use std::path::{Path, PathBuf};
use std::time::Instant;

use kiln_format::ContentHash;
use kiln_format::manifest::InputFile;
use serde::Serialize;

use crate::analyze::geometry::SceneGeometry;
use crate::analyze::plan::Plan;
use crate::analyze::validate;
use crate::bake::{self, BakeContext, StageReport};
use crate::cache::Cache;
use crate::cli::{BakeArgs, OutputArgs, SceneArgs};
use crate::exit::{CliError, CliResult};
use crate::import::{self, sidecar::Sidecar};
use crate::ir::{Scene, WarningClass};
use crate::progress::Progress;
use crate::settings::Settings;
use crate::warnings::{WarningLevel, WarningPolicy};

/// A scene ready to bake.
#[derive(Debug)]
pub struct Loaded {
    /// The validated scene.
    pub scene: Scene,
    /// Its geometry, shared by the plan and the bake.
    pub geometry: SceneGeometry,
    /// Settings in effect.
    pub settings: Settings,
    /// The plan.
    pub plan: Plan,
    /// Wall time of import, sidecar and validation, ms.
    pub import_ms: f64,
    /// Where the manifest records `scene.inputs` from: `(first, folder)` pairs in order, each
    /// input relative to the folder of the last pair whose `first` is at most its index (the
    /// scene file's folder for the asset's files, the sidecar's for it and the files it names).
    /// Empty: relative to the first input's folder.
    pub input_bases: Vec<(usize, PathBuf)>,
}

impl Loaded {
    /// The bake's context: builds the BVH.
    pub fn context<'a>(
        &'a self,
        inputs: Vec<InputFile>,
        progress: &'a Progress,
        cache: Option<&'a Cache>,
    ) -> CliResult<BakeContext<'a>> {
        BakeContext::new(&self.scene, &self.geometry, &self.settings, &self.plan, inputs, progress, cache)
    }
}

/// A warning in the report.
#[derive(Debug, Clone, Serialize)]
pub struct ReportWarning {
    /// Its class (`data-loss`, `missing-setup`).
    pub class: crate::ir::WarningClass,
    /// The message.
    pub message: String,
}

/// Imports, applies the sidecar, validates and plans. Warnings are printed to stderr unless
/// `quiet` (for callers that are not the command line: the command line's `-q` never hides a
/// warning); `--strict` and `-W` decide which classes of warning fail it.
pub fn load(args: &SceneArgs, quiet: bool) -> CliResult<Loaded> {
    let start = Instant::now();
    import::files::set_limits(
        args.max_file_size.unwrap_or(import::files::DEFAULT_MAX_FILE_BYTES),
        args.max_image_side.unwrap_or(import::files::DEFAULT_MAX_IMAGE_SIDE),
    );
    args.limits.apply(Some(&args.input), args.config.as_deref(), &args.bake);
    // The sidecar is read first since its `[bake] normals` decides the import; it is recorded
    // as an input after the asset, in the order a reader of the depfile expects.
    let mut sidecar_inputs = Vec::new();
    let sidecar = match args.config.as_deref() {
        Some(cfg) => Some((cfg, Sidecar::load(cfg, &mut sidecar_inputs)?)),
        None => None,
    };
    let settings = bake_settings(sidecar.as_ref().map(|(c, s)| (*c, s)), &args.bake)?;
    let mut scene = import::import_with(&args.input, settings.normals)?;
    let mut input_bases = vec![(0, folder_of(&args.input))];
    if let Some((cfg, _)) = &sidecar {
        input_bases.push((scene.inputs.len(), folder_of(cfg)));
    }
    for p in sidecar_inputs {
        if !scene.inputs.contains(&p) {
            scene.inputs.push(p);
        }
    }
    if let Some((cfg, sidecar)) = &sidecar {
        sidecar.apply(&mut scene, &cfg.display().to_string())?;
    }
    if let Some(crate::import::environment::EnvironmentSpec::Image { path, .. }) = &args.bake.environment {
        input_bases.push((scene.inputs.len(), folder_of(path)));
    }
    args.bake.apply_environment(&mut scene)?;
    let policy = WarningPolicy::new(args.strict, &args.warning_levels);
    let mut loaded = finish(scene, settings, &args.input.display().to_string(), &policy, quiet, start)?;
    loaded.input_bases = input_bases;
    Ok(loaded)
}

/// The folder holding `file`, absolute and resolved by name: links are not followed, since a
/// sandboxed build links each input from somewhere else and the layout the build gave the files is
/// the one to record.
fn folder_of(file: &Path) -> PathBuf {
    let p = import::files::lexical(file);
    p.parent().map_or(p.clone(), Path::to_path_buf)
}

/// The bake settings: the sidecar's `[bake]` table (if any), overridden by the command line's.
fn bake_settings(sidecar: Option<(&Path, &Sidecar)>, bake: &BakeArgs) -> CliResult<Settings> {
    let mut settings = Settings::default();
    if let Some((cfg, sidecar)) = sidecar {
        settings
            .apply_bake_table(&sidecar.bake)
            .map_err(|e| CliError::input(format!("{}: [bake] {e}", cfg.display())))?;
    }
    bake.apply(&mut settings);
    Ok(settings)
}

/// Applies a sidecar (if any) to a scene built in code (the demo) and returns the bake settings.
pub fn configure(scene: &mut Scene, config: Option<&Path>, bake: &BakeArgs) -> CliResult<Settings> {
    let sidecar = config.map(|cfg| Sidecar::load(cfg, &mut scene.inputs).map(|s| (cfg, s))).transpose()?;
    if let Some((cfg, sidecar)) = &sidecar {
        sidecar.apply(scene, &cfg.display().to_string())?;
    }
    bake.apply_environment(scene)?;
    bake_settings(sidecar.as_ref().map(|(c, s)| (*c, s)), bake)
}

/// Validates and plans an imported scene (also the entry point of the demo).
pub fn finish(
    mut scene: Scene,
    settings: Settings,
    source: &str,
    policy: &WarningPolicy,
    quiet: bool,
    start: Instant,
) -> CliResult<Loaded> {
    let valid = validate::finish(&mut scene, source);
    // The classes of the warnings that fail the compile, each once.
    let mut failing_classes: Vec<WarningClass> =
        policy.failing(&scene.warnings).iter().map(|w| w.class).collect();
    let failing = failing_classes.len();
    failing_classes.sort_unstable();
    failing_classes.dedup();
    // Warnings first, also when validation failed: they often explain the failure.
    if !quiet || failing > 0 || valid.is_err() {
        for w in &scene.warnings {
            if policy.level(w.class) != WarningLevel::Ignore {
                eprintln!("warning: {} [{}]", w.message, w.class.name());
            }
        }
    }
    valid?;
    if failing > 0 {
        let classes: Vec<&str> = failing_classes.iter().map(|c| c.name()).collect();
        return Err(CliError::input(format!(
            "{failing} warning(s) of class {} and --strict or -W CLASS=error is set",
            classes.join(", ")
        )));
    }
    let geometry = SceneGeometry::new(&scene);
    let plan = Plan::new(&scene, &geometry, &settings).map_err(CliError::usage)?;
    let import_ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(Loaded { scene, geometry, settings, plan, import_ms, input_bases: Vec::new() })
}

/// Validates, plans and bakes `scene` in memory, quietly and on the calling thread's pool, with no
/// input files recorded: the bytes `kiln compile` would write (tests and benchmarks build their
/// scenes in code).
pub fn compile_to_bytes(scene: Scene, settings: Settings, source: &str) -> CliResult<Vec<u8>> {
    let loaded = finish(scene, settings, source, &WarningPolicy::default(), true, Instant::now())?;
    bake_to_bytes(&loaded)
}

/// Bakes a loaded scene in memory, quietly, with no input files recorded and no cache.
pub fn bake_to_bytes(loaded: &Loaded) -> CliResult<Vec<u8>> {
    let progress = Progress::hidden();
    let baked = bake::bake(&loaded.context(Vec::new(), &progress, None)?)?;
    bake::to_bytes(&baked).map_err(|e| CliError::io(e.to_string()))
}

/// Reads and hashes every input file for the manifest. Each is recorded by its path relative to
/// the folder `bases` gives it (see [`Loaded::input_bases`]; without bases the first input's: the
/// demo's sidecar), `/`-separated, so that the same files compiled from another folder, named
/// another way (`./a.gltf`, `/abs/a.gltf`, `sub/../a.gltf`) or with the sidecar kept elsewhere give
/// the same bytes: a build system's cache is shared between machines whose checkouts sit in
/// different places. The depfile and the report keep the paths as given.
pub fn hash_inputs(paths: &[PathBuf], bases: &[(usize, PathBuf)]) -> CliResult<Vec<InputFile>> {
    let first = paths.first().map(|p| folder_of(p));
    paths
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let bytes = std::fs::read(p).map_err(|e| CliError::io(format!("{}: {e}", p.display())))?;
            let base = bases.iter().rev().find(|(start, _)| *start <= i).map(|(_, b)| b).or(first.as_ref());
            let path = match base {
                Some(base) => relative_path(base, &import::files::lexical(p)),
                None => p.display().to_string(),
            };
            Ok(InputFile { path, bytes: bytes.len() as u64, hash: ContentHash::of(&bytes).to_hex() })
        })
        .collect()
}

/// The `/`-separated path from folder `base` to `p` (both absolute and lexically normal), with
/// `..` where `p` lies outside `base`.
fn relative_path(base: &Path, p: &Path) -> String {
    let (b, t): (Vec<_>, Vec<_>) = (base.components().collect(), p.components().collect());
    let common = b.iter().zip(&t).take_while(|(x, y)| x == y).count();
    let mut parts: Vec<String> = vec!["..".to_string(); b.len() - common];
    parts.extend(t[common..].iter().map(|c| c.as_os_str().to_string_lossy().into_owned()));
    parts.join("/")
}

/// Counts for reports.
#[derive(Debug, Clone, Serialize)]
pub struct Counts {
    /// Triangles written.
    pub triangles: usize,
    /// Vertices written.
    pub vertices: usize,
    /// Materials.
    pub materials: usize,
    /// Textures.
    pub textures: usize,
    /// Lights.
    pub lights: usize,
    /// Cameras.
    pub cameras: usize,
    /// BVH nodes.
    pub bvh_nodes: usize,
    /// Degenerate triangles dropped.
    pub degenerate_triangles: u64,
}

/// The JSON report of one compile.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Input path (or "demo").
    pub input: String,
    /// Output path.
    pub output: String,
    /// Output size.
    pub bytes: u64,
    /// Total wall time, ms.
    pub total_ms: f64,
    /// Worker threads.
    pub threads: usize,
    /// The stage cache directory, when one was used.
    pub cache: Option<String>,
    /// Settings in effect.
    pub settings: Vec<(String, String)>,
    /// Per-stage timing and size, including `import` and `write`.
    pub stages: Vec<StageReport>,
    /// Counts.
    pub counts: Counts,
    /// Every warning, with its class (ignored ones too).
    pub warnings: Vec<ReportWarning>,
    /// Every file read.
    pub inputs: Vec<String>,
    /// Voxel grid and line space figures (memory per variant), when baked.
    pub line_space: Option<crate::bake::LineSpaceStats>,
    /// The plan's line-space configuration and its size estimate, when baked.
    pub line_space_plan: Option<crate::analyze::budget::Choice>,
    /// Bytes of the grid and line-space sections written (to compare with the estimate).
    pub line_space_bytes: u64,
    /// Per texture: stored format, bytes, and the error of mip 0 against the RGBA8 texels.
    pub textures: Vec<crate::bake::bc::TextureReport>,
}

/// Bakes and writes `loaded` to `output`; writes the report and depfile if asked.
pub fn compile(loaded: &Loaded, input_name: &str, output: &Path, out: &OutputArgs) -> CliResult<Report> {
    let start = Instant::now();
    // Before any work: no output may replace an input (or another output).
    let mut outputs: Vec<(&str, &Path)> = vec![("-o", output)];
    outputs.extend(out.report.as_deref().map(|p| ("--report", p)));
    outputs.extend(out.depfile.as_deref().map(|p| ("--depfile", p)));
    crate::clobber::refuse(&outputs, &loaded.scene.inputs)?;
    let threads =
        out.threads.map_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()), usize::from);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| CliError::io(format!("cannot start {threads} worker threads: {e}")))?;
    let cache = out.cache_dir().map(|d| Cache::open(&d)).transpose()?;
    crate::bake::linespace::gpu::choose(out.line_space_device);
    // A line space large enough for the GPU: open it while the earlier stages run.
    let plan = &loaded.plan;
    let work = crate::bake::linespace::gpu::planned_work(
        plan.shaft_variants,
        plan.pnmt_layout,
        !loaded.scene.uvs.is_empty(),
        plan.shaft_res,
        || loaded.geometry.voxels(plan.voxel_res).triangles.len(),
    );
    if let Some(work) = work {
        crate::bake::linespace::gpu::open_early(work, plan.shaft_res, plan.pnmt_layout);
    }
    let progress = Progress::new(!out.quiet);
    let inputs = hash_inputs(&loaded.scene.inputs, &loaded.input_bases)?;
    let baked = pool.install(|| bake::bake(&loaded.context(inputs, &progress, cache.as_ref())?));
    let written = baked.and_then(|baked| {
        progress.stage("write");
        let t_write = Instant::now();
        let bytes = bake::write(&baked, output, threads).map_err(|e| CliError::io(e.to_string()))?;
        Ok((baked, bytes, t_write.elapsed().as_secs_f64() * 1e3))
    });
    // After the write: a GPU opened early for a line space that then came from the stage cache
    // (half a second on the H200 machine) finishes opening while the sections are compressed.
    crate::bake::linespace::gpu::finish();
    let (baked, bytes, write_ms) = written?;
    progress.finish();
    let mut stages = vec![StageReport {
        stage: "import",
        run: true,
        cached: false,
        reason: "read, validate and plan".into(),
        ms: loaded.import_ms,
        bytes: baked.manifest.inputs.iter().map(|i| i.bytes).sum(),
    }];
    stages.extend(baked.stages.iter().cloned());
    stages.push(StageReport {
        stage: "write",
        run: true,
        cached: false,
        reason: "atomic write".into(),
        ms: write_ms,
        bytes,
    });
    let s = &loaded.scene;
    let report = Report {
        input: input_name.to_string(),
        output: output.display().to_string(),
        bytes,
        total_ms: loaded.import_ms + start.elapsed().as_secs_f64() * 1e3,
        threads,
        cache: cache.as_ref().map(|c| c.dir().display().to_string()),
        settings: loaded.settings.pairs(),
        stages,
        counts: Counts {
            triangles: s.triangles.len(),
            vertices: s.vertices.len(),
            materials: s.materials.len(),
            textures: s.textures.len(),
            lights: s.lights.len(),
            cameras: s.cameras.len(),
            bvh_nodes: baked
                .sections
                .iter()
                .find(|x| x.kind == kiln_format::sections::BVH_NODES)
                .map_or(0, |x| x.bytes.len() / 80),
            degenerate_triangles: s.degenerate_triangles,
        },
        warnings: s
            .warnings
            .iter()
            .map(|w| ReportWarning { class: w.class, message: w.message.clone() })
            .collect(),
        inputs: s.inputs.iter().map(|p| p.display().to_string()).collect(),
        line_space: baked.line_space.clone(),
        line_space_plan: loaded.plan.line_space.clone(),
        line_space_bytes: baked
            .sections
            .iter()
            .filter(|x| {
                x.kind == kiln_format::sections::GRID || kiln_format::linespace::SECTIONS.contains(&x.kind)
            })
            .map(|x| x.bytes.len() as u64)
            .sum(),
        textures: baked.textures.clone(),
    };
    if let Some(path) = &out.report {
        let json = serde_json::to_string_pretty(&report).map_err(|e| CliError::io(e.to_string()))?;
        std::fs::write(path, json + "\n").map_err(|e| CliError::io(format!("{}: {e}", path.display())))?;
    }
    if let Some(path) = &out.depfile {
        std::fs::write(path, depfile(output, &s.inputs))
            .map_err(|e| CliError::io(format!("{}: {e}", path.display())))?;
    }
    Ok(report)
}

/// A make/ninja depfile: `OUT: IN...`, spaces, `#` and `\` escaped with `\`, `$` as `$$`.
pub fn depfile(output: &Path, inputs: &[PathBuf]) -> String {
    let esc = |p: &Path| {
        let mut s = String::new();
        for c in p.display().to_string().chars() {
            match c {
                ' ' | '#' | '\\' => {
                    s.push('\\');
                    s.push(c);
                }
                '$' => s.push_str("$$"),
                _ => s.push(c),
            }
        }
        s
    };
    let mut out = format!("{}:", esc(output));
    for i in inputs {
        out.push_str(" \\\n  ");
        out.push_str(&esc(i));
    }
    out.push('\n');
    out
}
