//! Command-line definition (clap). Raw values are checked here; commands turn them into settings.

use std::path::{Path, PathBuf};

use clap::{Args, Parser, Subcommand};

use crate::settings::{
    BRDF_LUT_RES, BvhPreset, Codec, LINE_SPACE_BUDGET, MEDIA_VOLUME_RES, Normals, PnmtRecords, SHADOW_RES,
    SHAFT_RES, Settings, TextureFormat, VOXEL_RES, VoxelRes, parse_variants,
};

/// kiln compiles glTF and OBJ scenes into .kiln files: geometry, textures, BVH and the baked
/// lighting structures a player needs, checksummed, versioned and ready to memory-map.
#[derive(Debug, Parser)]
#[command(name = "kiln", version, about, long_about = None, propagate_version = true)]
#[command(after_help = "Exit codes: 0 success, 1 bad input or failed verification, 2 usage error, \
3 unsupported (e.g. another major format version), 4 I/O failure.")]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Compile a glTF (.gltf, .glb) or OBJ scene into a .kiln file.
    Compile(CompileArgs),
    /// Show every bake stage with run or skip and the reason, without writing anything.
    Plan(PlanArgs),
    /// Compile a built-in scene: the demo Cornell box, or a benchmark scene of seed 004
    /// (`--scene`).
    Demo(DemoArgs),
    /// Write an image-like section (brdf-lut, shadow-map, texture, media-visibility) as PFM or
    /// EXR (float) or PNG, chosen by the output's extension.
    Export(ExportArgs),
    /// Show a .kiln file's version, sections (kind, size, codec, checksum status) and manifest.
    Inspect(InspectArgs),
    /// Validate a .kiln file completely: layout, every checksum, every cross-reference.
    /// Exits 0 when the file is sound; otherwise prints one line saying what is wrong and where.
    Verify(VerifyArgs),
    /// Show or trim a stage cache (see `kiln compile --cache`).
    #[command(subcommand)]
    Cache(CacheCommand),
    /// Write shell completions for SHELL to stdout (e.g. `kiln completions bash >
    /// /etc/bash_completion.d/kiln`).
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Write the man page (roff) to stdout (`kiln man > kiln.1`).
    Man,
}

/// `kiln cache`.
#[derive(Debug, Subcommand)]
pub enum CacheCommand {
    /// Entries and bytes of a stage cache, in all and per stage.
    Stats {
        /// The cache directory [default: $KILN_CACHE].
        dir: Option<PathBuf>,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Remove least recently used entries (a compile's hit counts as a use) until the cache
    /// takes at most SIZE; also removes temporary files over a day old.
    Gc {
        /// The cache directory [default: $KILN_CACHE].
        dir: Option<PathBuf>,
        /// The size to trim to: bytes, or with a binary unit K, M, G, T (e.g. 500M, 2G).
        #[arg(long, value_name = "SIZE", value_parser = crate::cache::parse_size)]
        max_size: u64,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
}

/// `kiln inspect`.
#[derive(Debug, Args)]
pub struct InspectArgs {
    /// The .kiln file.
    pub file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `kiln verify`.
#[derive(Debug, Args)]
pub struct VerifyArgs {
    /// The .kiln file.
    pub file: PathBuf,
    /// Also trace N seeded rays (random, aimed at triangles, and adversarial: axis-aligned,
    /// through vertices and edges, grazing, starting on surfaces) through the baked BVH and by
    /// brute force over all triangles, and count disagreements of the closest hit.
    #[arg(long, value_name = "N")]
    pub rays: Option<u64>,
    /// Seed of the ray generator.
    #[arg(long, default_value_t = 1, requires = "rays")]
    pub seed: u64,
    /// Print a JSON report instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Options shared by commands that import a scene.
#[derive(Debug, Args, Clone)]
pub struct SceneArgs {
    /// Input scene: .gltf, .glb or .obj.
    pub input: PathBuf,
    /// TOML sidecar with what the asset lacks: camera, lights, sky, media, material fixes,
    /// bake settings (see docs/sidecar.md).
    #[arg(long, short = 'c', value_name = "SIDECAR.toml")]
    pub config: Option<PathBuf>,
    /// Bake settings.
    #[command(flatten)]
    pub bake: BakeArgs,
    /// Fail on warnings of data loss (an unreadable image, an unsupported extension, a skipped
    /// primitive, ...); warnings of missing setup (no camera, nothing lights the scene) stay
    /// warnings, since a sidecar supplies those.
    #[arg(long)]
    pub strict: bool,
    /// How a class of warnings is treated: CLASS=error|warn|ignore with CLASS data-loss or
    /// missing-setup (repeatable; applied after --strict, the last setting of a class winning).
    /// Ignored warnings are not printed but stay in the --report.
    #[arg(short = 'W', long = "warnings", value_name = "CLASS=LEVEL", value_parser = crate::warnings::parse_setting)]
    pub warning_levels: Vec<(crate::ir::WarningClass, crate::warnings::WarningLevel)>,
    /// The largest file the import reads (the asset, its buffers, images and MTL libraries):
    /// bytes, or with a binary unit K, M, G, T. Only regular files are read [default: 4G].
    #[arg(long, value_name = "SIZE", value_parser = crate::cache::parse_size, help_heading = "Input limits")]
    pub max_file_size: Option<u64>,
    /// The largest image side in pixels the import decodes, read from the image's header before
    /// decoding; a larger image is not decoded (a data-loss warning) [default: 4096; 8K textures and
    /// environment maps need 8192].
    #[arg(long, value_name = "PIXELS", value_parser = clap::value_parser!(u32).range(1..), help_heading = "Input limits")]
    pub max_image_side: Option<u32>,
    /// Where files the asset names may lie, and what the bake may spend.
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// Where the files an asset names (buffers, images, MTL libraries, the sidecar's sky image) may
/// lie (files named on the command line are always read), and what the bake may spend. Limits
/// are flags only: a sidecar travels with the asset and must not raise them.
#[derive(Debug, Args, Clone, Default)]
pub struct LimitArgs {
    /// Also let the asset and the sidecar read files under DIR (repeatable). By default they may
    /// read only under the input's folder and the sidecar's: an asset naming `../../etc/passwd`
    /// or an absolute path elsewhere is refused.
    #[arg(long, value_name = "DIR", help_heading = "Input limits")]
    pub search_path: Vec<PathBuf>,
    /// Let the asset read files anywhere (only for assets you trust).
    #[arg(long, help_heading = "Input limits", conflicts_with = "search_path")]
    pub allow_any_path: bool,
    /// The most memory the baked products the settings size may take together (shadow maps,
    /// light-visibility volumes, voxel grid and line space, probes, environment): bytes, or with
    /// a binary unit K, M, G, T. Settings whose product exceeds it are a usage error naming them
    /// [default: 1G].
    #[arg(long, value_name = "SIZE", value_parser = crate::cache::parse_size, help_heading = "Input limits")]
    pub max_bake_memory: Option<u64>,
    /// The most rays the settings may ask the bakes to trace (a texel of a shadow map, a sample
    /// of a light-visibility volume), with an optional unit K, M, G (powers of 1024)
    /// [default: 32M].
    #[arg(long, value_name = "N", value_parser = crate::cache::parse_size, help_heading = "Input limits")]
    pub max_bake_rays: Option<u64>,
}

impl LimitArgs {
    /// Sets the bake limits, and the confinement for an import of `input` (none for the demo)
    /// with `sidecar`, where `bake` may name an environment file on the command line.
    pub fn apply(&self, input: Option<&Path>, sidecar: Option<&Path>, bake: &BakeArgs) {
        use crate::analyze::limits;
        limits::set_bake_limits(
            self.max_bake_memory.unwrap_or(limits::DEFAULT_MAX_BAKE_MEMORY),
            self.max_bake_rays.unwrap_or(limits::DEFAULT_MAX_BAKE_RAYS),
        );
        if self.allow_any_path {
            crate::import::files::confine(None);
            return;
        }
        let folder = |p: &Path| match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let named: Vec<PathBuf> = input.into_iter().chain(sidecar).map(Path::to_path_buf).collect();
        let mut roots: Vec<PathBuf> = named.iter().map(|p| folder(p)).collect();
        // Also the folder each named file really lies in, when it is a link: a sandboxed build
        // (Bazel, Buck2) gives the action a folder of links to the source files, and the files
        // an asset names resolve beside the asset's own real file.
        roots.extend(named.iter().filter_map(|p| p.canonicalize().ok()).map(|p| folder(&p)));
        roots.extend(self.search_path.iter().cloned());
        let mut files = named;
        if let Some(crate::import::environment::EnvironmentSpec::Image { path, .. }) = &bake.environment {
            files.push(path.clone());
        }
        crate::import::files::confine(Some((&roots, &files)));
    }
}

/// Bake settings, shared by `compile`, `plan` and `demo`; each overrides the sidecar's or the
/// default setting when given. Ranges and defaults come from the tables in [`crate::settings`].
#[derive(Debug, Args, Clone, Default)]
pub struct BakeArgs {
    /// BVH build effort.
    #[arg(
        long,
        value_enum,
        help_heading = "BVH",
        help = "BVH build effort [default: medium, or the sidecar's bake.bvh_preset]"
    )]
    pub bvh_preset: Option<BvhPreset>,
    /// Voxel grid cells along the longest axis, or `auto`.
    #[arg(long, value_name = "N|auto", value_parser = VoxelRes::parse, help_heading = "Voxel grid and line space",
          help = format!("Voxel grid cells along the scene's longest axis (cubic cells, {}..={}), or `auto`: the cube root of the triangle count, clamped to 4..=64 [default: auto]", VOXEL_RES.min, VOXEL_RES.max))]
    pub voxel_res: Option<VoxelRes>,
    /// Shaft resolution N.
    #[arg(long, value_name = "N", value_parser = SHAFT_RES.parser(), help_heading = "Voxel grid and line space",
          help = SHAFT_RES.help("Shaft resolution N: patches per voxel face edge, 15·N⁴ shafts per voxel"))]
    pub shaft_res: Option<u32>,
    /// Line-space variants to bake, comma-separated: binary (one bit per shaft), candidates
    /// (exact triangle lists), pnmt (front/back hit records), preillum (front/back radiance under
    /// the static lights), or none [default: chosen by the plan].
    #[arg(long, value_name = "LIST", value_parser = parse_variants, help_heading = "Voxel grid and line space")]
    pub shaft_variants: Option<u32>,
    /// Size budget of the grid and line space, MiB.
    #[arg(long, value_name = "MiB", value_parser = LINE_SPACE_BUDGET.parser(), help_heading = "Voxel grid and line space",
          help = format!("Size budget of the voxel grid and line space in MiB: lowers the voxel resolution, then N (those not given), and drops candidates, then PNMT (when --shaft-variants is not given), until the estimate fits; a usage error if nothing fits, {}..={}. [default: {}x the bytes of the geometry sections, within {}..={} MiB; it applies only when the plan chooses the variants]", LINE_SPACE_BUDGET.min, LINE_SPACE_BUDGET.max, crate::analyze::budget::DEFAULT_BUDGET_PER_GEOMETRY, crate::analyze::budget::DEFAULT_BUDGET_MIN_MIB, crate::analyze::budget::DEFAULT_BUDGET_MAX_MIB))]
    pub line_space_budget: Option<u32>,
    /// How PNMT records are stored.
    #[arg(
        long,
        value_enum,
        help_heading = "Voxel grid and line space",
        help = "How PNMT records are stored: compact (12 bytes a record, 8 where no material samples a \
texture: positions to 1/1023 of a cell, normals within 0.12°, up to 4,095 materials, beyond which full is \
used) or full (16 bytes: positions to 1/65535 of a cell, normals within 0.005°). The compact error is far \
below PNMT's own (a shaft's midpoint ray stands for rays up to a patch apart) [default: compact, or the \
sidecar's bake.pnmt_records]"
    )]
    pub pnmt_records: Option<PnmtRecords>,
    /// BRDF lookup table size N.
    #[arg(long, value_name = "N", value_parser = BRDF_LUT_RES.parser(), help_heading = "Lighting bakes",
          help = BRDF_LUT_RES.help("BRDF lookup table size N (N × N texels)"))]
    pub brdf_lut_res: Option<u32>,
    /// Shadow map size N.
    #[arg(long, value_name = "N", value_parser = SHADOW_RES.parser(), help_heading = "Lighting bakes",
          help = SHADOW_RES.help("Shadow map size N (N × N for directional and spot lights; cube faces of N/2)"))]
    pub shadow_res: Option<u32>,
    /// Light-visibility volume cells along the medium's longest axis.
    #[arg(long, value_name = "N", value_parser = MEDIA_VOLUME_RES.parser(), help_heading = "Lighting bakes",
          help = MEDIA_VOLUME_RES.help("Light-visibility volume cells along the medium's longest axis"))]
    pub media_volume_res: Option<u32>,
    /// Whether the irradiance probe volume is baked.
    #[arg(
        long,
        value_enum,
        help_heading = "Lighting bakes",
        help = format!("Irradiance probes (read by kiln-play {}): auto (a volume of probes path traced at every \
bounce, whenever something lights the scene) or off [default: auto, or the sidecar's bake.probes]", kiln_format::readers::list(kiln_format::readers::PROBES))
    )]
    pub probes: Option<crate::settings::Probes>,
    /// Distance between probes.
    #[arg(long, value_name = "UNITS", value_parser = crate::settings::ProbeSpacing::parse, allow_negative_numbers = true, help_heading = "Lighting bakes",
          help = format!("Distance between irradiance probes in scene units [default: the longest extent over {}, widened until the volume fits --probe-budget]", crate::bake::probes::AUTO_PROBES))]
    pub probe_spacing: Option<crate::settings::ProbeSpacing>,
    /// Rays per probe.
    #[arg(long, value_name = "N", value_parser = crate::settings::PROBE_RAYS.parser(), help_heading = "Lighting bakes",
          help = format!("Paths traced per probe (more: less noise, longer bake), {}..={} [default: {} where every material is Lambertian, {} where one is glossy]", crate::settings::PROBE_RAYS.min, crate::settings::PROBE_RAYS.max, crate::settings::PROBE_RAYS.default, crate::settings::PROBE_RAYS_GLOSSY))]
    pub probe_rays: Option<u32>,
    /// Budget of the probe volume.
    #[arg(long, value_name = "MiB", value_parser = crate::settings::PROBE_BUDGET.parser(), help_heading = "Lighting bakes",
          help = crate::settings::PROBE_BUDGET.help("Size budget of the probe volume in MiB when --probe-spacing is not given"))]
    pub probe_budget: Option<u32>,
    /// Least roughness of the surfaces the probe paths meet.
    #[arg(long, value_name = "R", value_parser = crate::settings::ProbeRegularize::parse, help_heading = "Lighting bakes",
          help = format!("Path regularisation of the probe bake: the surfaces its paths meet are treated as at least \
this rough (perceptual roughness, 0 to 1; 0: as the asset says). Probes store irradiance, where a glossy \
highlight counts for its energy, not its sharpness: widening it keeps the energy and removes the fireflies \
of highlights one path in thousands catches [default: {}]", crate::settings::ProbeRegularize::DEFAULT.0))]
    pub probe_regularize: Option<crate::settings::ProbeRegularize>,
    /// Width of the environment's radiance map.
    #[arg(long, value_name = "N", value_parser = crate::settings::ENVIRONMENT_RES.parser(), help_heading = "Environment",
          help = crate::settings::ENVIRONMENT_RES.help("Width of the environment's radiance map in texels (height half of it; a narrower image keeps its width). Its GGX-prefiltered levels (256 wide at most), irradiance harmonics and sampling table (512 wide at most) are baked from it"))]
    pub environment_res: Option<u32>,
    /// The environment: studio, preetham, or an HDR image.
    #[arg(long, value_name = "studio|preetham|FILE", value_parser = crate::import::environment::EnvironmentSpec::parse, help_heading = "Environment",
          help = "Light from every direction beyond the scene, replacing the sidecar's [sky]: `studio` (a built-in \
neutral dome with a key softbox and a rim light, for assets that bring no light), `preetham` (Preetham's daylight \
with its sun as a directional light, at the default sun 45° up and turbidity 3; a sidecar's [sky] model = \
\"preetham\" chooses others), or an \
equirectangular Radiance .hdr or OpenEXR image (see docs/sidecar.md)")]
    pub environment: Option<crate::import::environment::EnvironmentSpec>,
    /// Whether a sun in an --environment image becomes a directional light.
    #[arg(long, value_name = "on|off", value_parser = ["on", "off"], requires = "environment", help_heading = "Environment",
          help = "With an --environment image: `on` takes a sun found in it (a region under 0.01 sr, 64 times brighter \
than the map's median) out of the map as a directional light of the same irradiance, which shadow maps and shadow \
rays then see (the disc's size is lost: hard shadows); `off` leaves it in the map [default: on]")]
    pub environment_sun: Option<String>,
    /// Multiplies the environment's radiance.
    #[arg(
        long,
        value_name = "X",
        requires = "environment",
        help_heading = "Environment",
        help = "Multiplies the --environment's radiance (and the Preetham sun's) [default: 1]"
    )]
    pub environment_intensity: Option<f32>,
    /// Rotates the environment about +y.
    #[arg(
        long,
        value_name = "DEGREES",
        requires = "environment",
        help_heading = "Environment",
        help = "Rotates the --environment about +y by the right-hand rule (counter-clockwise seen from above: 90 turns what lay along -z to -x) [default: 0]"
    )]
    pub environment_rotation: Option<f32>,
    /// Normals where the asset gives none.
    #[arg(long, value_name = "flat|smooth[:ANGLE]", value_parser = Normals::parse, help_heading = "Import",
          help = "Normals where the asset gives none (given normals are kept): flat (face normals), smooth \
(angle-weighted vertex normals), smooth:ANGLE (smooth except across edges whose faces differ by more \
than ANGLE degrees) [default: asset: glTF flat as its spec says, OBJ by its smoothing groups]")]
    pub normals: Option<Normals>,
    /// Which sections are stored compressed.
    #[arg(long, value_name = "auto|none|zstd", value_parser = Codec::parse, help_heading = "Output",
          help = "Section compression: auto (zstd for every section it shrinks by at least 1/8: the player \
decodes them on all cores while the driver creates the device; sections that barely shrink stay as is, \
zero-copy), none (every section as is: no decoding at all), zstd (every section that shrinks: smallest \
file, for distribution) [default: auto, or the sidecar's bake.codec]")]
    pub codec: Option<Codec>,
    /// How textures are stored.
    #[arg(
        long,
        value_enum,
        help_heading = "Textures",
        help = "How textures are stored: bc (block-compressed by role: BC7 colour and sRGB, BC5 normal maps \
and metallic-roughness, BC4 occlusion; 4 to 8 times smaller than rgba8, error per texture in the report; the \
player needs textureCompressionBC) or rgba8 (exact, every device) [default: bc, or the sidecar's \
bake.texture_format]"
    )]
    pub texture_format: Option<TextureFormat>,
}

impl BakeArgs {
    /// Applies the options given to `settings`.
    pub fn apply(&self, settings: &mut Settings) {
        fn set<T: Copy>(setting: &mut T, given: Option<T>) {
            if let Some(v) = given {
                *setting = v;
            }
        }
        set(&mut settings.bvh_preset, self.bvh_preset);
        set(&mut settings.voxel_res, self.voxel_res);
        set(&mut settings.shaft_res, self.shaft_res.map(Some));
        set(&mut settings.line_space_budget, self.line_space_budget.map(Some));
        set(&mut settings.shaft_variants, self.shaft_variants.map(Some));
        set(&mut settings.brdf_lut_res, self.brdf_lut_res);
        set(&mut settings.shadow_res, self.shadow_res);
        set(&mut settings.media_volume_res, self.media_volume_res);
        set(&mut settings.probes, self.probes);
        set(&mut settings.probe_spacing, self.probe_spacing.map(Some));
        set(&mut settings.probe_rays, self.probe_rays.map(Some));
        set(&mut settings.probe_budget, self.probe_budget);
        set(&mut settings.probe_regularize, self.probe_regularize);
        set(&mut settings.environment_res, self.environment_res);
        set(&mut settings.normals, self.normals);
        set(&mut settings.codec, self.codec);
        set(&mut settings.texture_format, self.texture_format);
        set(&mut settings.pnmt_records, self.pnmt_records);
    }
}

impl BakeArgs {
    /// Sets `scene`'s environment from `--environment` (when given), replacing the sidecar's.
    pub fn apply_environment(&self, scene: &mut crate::ir::Scene) -> crate::exit::CliResult<()> {
        use crate::import::environment::{Placement, apply};
        let Some(spec) = &self.environment else { return Ok(()) };
        let mut spec = spec.clone();
        if let crate::import::environment::EnvironmentSpec::Image { extract_sun, .. } = &mut spec {
            *extract_sun = self.environment_sun.as_deref() != Some("off");
        }
        let d = Placement::default();
        let placement = Placement {
            intensity: self.environment_intensity.unwrap_or(d.intensity),
            rotation_degrees: self.environment_rotation.unwrap_or(d.rotation_degrees),
        };
        apply(scene, &spec, placement, "--environment")
    }
}

/// Options of commands that write a file.
#[derive(Debug, Args, Clone)]
pub struct OutputArgs {
    /// Write a JSON report: per-stage wall time and bytes, counts, skips with reasons, warnings.
    #[arg(long, value_name = "REPORT.json")]
    pub report: Option<PathBuf>,
    /// Write a make/ninja depfile listing every file read.
    #[arg(long, value_name = "DEPS.d")]
    pub depfile: Option<PathBuf>,
    /// Worker threads for the bakes and the compression [default: all cores]. The output is
    /// identical for every count.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub threads: Option<u16>,
    /// Where the line space is baked. The output is identical for every device.
    #[arg(
        long,
        value_enum,
        default_value_t,
        help = "Where the line space is baked: auto (a GPU through Vulkan compute where one opens and \
the bake is large enough to gain from it, else the CPU), cpu, or gpu (an error without one). The output \
is identical for every device; the GPU bakes the binary and PNMT variants, the CPU the rest"
    )]
    pub line_space_device: crate::bake::linespace::gpu::BakeDevice,
    /// Print nothing but errors and warnings: no progress, no summary (warnings are hidden only
    /// by -W CLASS=ignore).
    #[arg(long, short = 'q')]
    pub quiet: bool,
    /// Stage cache directory: each bake stage's output is kept there under the hash of what the
    /// stage reads and reused by later compiles (the output is byte-identical either way).
    /// Created if missing. Without this option or KILN_CACHE nothing is kept [env: KILN_CACHE]
    #[arg(long, value_name = "DIR", help_heading = "Stage cache")]
    pub cache: Option<PathBuf>,
    /// Use no stage cache, even if KILN_CACHE is set.
    #[arg(long, conflicts_with = "cache", help_heading = "Stage cache")]
    pub no_cache: bool,
}

impl OutputArgs {
    /// The stage cache directory: --cache, else KILN_CACHE (unless --no-cache), else none.
    pub fn cache_dir(&self) -> Option<PathBuf> {
        if self.no_cache { None } else { crate::cache::Cache::dir_from(self.cache.as_deref()) }
    }
}

/// `kiln compile`.
#[derive(Debug, Args)]
pub struct CompileArgs {
    /// Scene and settings.
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output file [default: INPUT's name with .kiln, in the current directory].
    #[arg(long, short = 'o', value_name = "OUT.kiln")]
    pub output: Option<PathBuf>,
    /// Report, depfile, threads.
    #[command(flatten)]
    pub out: OutputArgs,
}

/// `kiln export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The .kiln file.
    pub file: PathBuf,
    /// Section name and index, e.g. `brdf-lut`, `shadow-map:1`, `texture:0`, `probe-irradiance:2`
    /// (the probes' z slice 2; the emitted layer's slices follow), `environment-map`,
    /// `environment-filtered:3` (the prefiltered level of roughness 3 / 5) (`kiln inspect` lists
    /// the sections a file has).
    pub section: String,
    /// Output image: .pfm, .exr or .png.
    #[arg(long, short = 'o', value_name = "PATH")]
    pub output: PathBuf,
    /// Print nothing but errors.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

/// `kiln plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Scene and settings.
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// A built-in scene of `kiln demo`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum DemoScene {
    /// The demo Cornell box: five walls, two blocks, a warm ceiling light, 30 triangles.
    #[default]
    Demo,
    /// Seed 004's scene 4: the Cornell box with two blocks and a light quad (32 triangles here:
    /// the blocks have no bottoms; the thesis's box has 36).
    Cornell,
    /// The 12-triangle box around a 15,704-triangle object (the Utah teapot's count).
    BoxTeapot,
    /// The 12-triangle box around a 69,451-triangle object (the Stanford bunny's count).
    BoxBunny,
    /// The 12-triangle box around an 871,306-triangle object (the Stanford dragon's count).
    BoxDragon,
}

/// `kiln demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Which scene: the demo, or one of seed 004's benchmark settings (Table 1) for
    /// `kiln-play FILE --bench-rays`; each has the demo's camera looking into the box. The objects
    /// are seeded bumpy spheres with the thesis meshes' triangle counts, not the meshes.
    #[arg(long, value_enum, default_value_t = DemoScene::Demo)]
    pub scene: DemoScene,
    /// Output file.
    #[arg(long, short = 'o', value_name = "OUT.kiln", default_value = "demo.kiln")]
    pub output: PathBuf,
    /// TOML sidecar applied to the demo scene as to an imported one (e.g. a [sky] to light the
    /// open front of the box; see docs/sidecar.md).
    #[arg(long, short = 'c', value_name = "SIDECAR.toml")]
    pub config: Option<PathBuf>,
    /// Bake settings.
    #[command(flatten)]
    pub bake: BakeArgs,
    /// Where files the sidecar names may lie, and what the bake may spend.
    #[command(flatten)]
    pub limits: LimitArgs,
    /// Report, depfile, threads.
    #[command(flatten)]
    pub out: OutputArgs,
}

/// Parses the process arguments; exits with code 2 and a usage message on error.
pub fn parse() -> Cli {
    Cli::parse()
}

/// Parses a command line (the program's name first), for running `kiln` in process (the public
/// corpus runner): clap's error on a usage error, as `kiln` would print it.
pub fn parse_from<I, T>(args: I) -> Result<Cli, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    Cli::try_parse_from(args)
}
