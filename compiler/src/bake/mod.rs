//! Bake stages: each a function of the [`BakeContext`] producing [`Sections`], one per file,
//! timed, with content hashes computed from what they depend on. [`bake`] runs the plan's stages
//! in order and assembles the manifest.

pub mod bc;
pub mod brdf_lut;
pub mod bvh;
pub mod context;
pub mod environment;
pub mod geometry;
pub mod linespace;
pub mod materials;
pub mod media;
pub mod probes;
pub mod shadow;
pub mod textures;
pub mod uvs;

pub use context::BakeContext;

use std::time::Instant;

use kiln_format::manifest::{
    BrdfLutInfo, InputFile, Manifest, MaterialInfo, MediaVisibilityInfo, Setting, ShadowMapInfo,
    SkippedStage, TextureInfo,
};
use kiln_format::{ContentHash, ContentHasher, SectionKind};
use serde::Serialize;

use crate::analyze::plan::Stage;
use crate::cache::{self, Cache};
use crate::exit::CliResult;
use crate::ir::Scene;

/// Bumped when a stage's algorithm changes its output, so that caches keyed by content hashes
/// do not reuse stale sections. 2: CWBVH planes widened past f32 rounding; the voxel grid padded
/// by four of its own margins. 3: the emissive triangles' mean luminance read at 16 to 64
/// sub-triangle centroids.
pub(crate) const ALGORITHM_VERSION: &str = "kiln-bake-3";

/// A baked section ready to be written.
#[derive(Debug, Clone)]
pub struct BakedSection {
    /// Kind.
    pub kind: SectionKind,
    /// Index.
    pub index: u32,
    /// Bytes.
    pub bytes: Vec<u8>,
    /// Content hash of what produced it.
    pub hash: ContentHash,
}

/// Timing and size of one stage, for the report.
#[derive(Debug, Clone, Serialize)]
pub struct StageReport {
    /// Stage name.
    pub stage: &'static str,
    /// Whether it ran.
    pub run: bool,
    /// Whether its output came from the stage cache (`--cache`) instead of being baked.
    pub cached: bool,
    /// Why it ran or was skipped.
    pub reason: String,
    /// Wall time in milliseconds.
    pub ms: f64,
    /// Bytes of the sections it produced.
    pub bytes: u64,
}

/// Everything to write.
#[derive(Debug, Clone)]
pub struct Baked {
    /// The manifest.
    pub manifest: Manifest,
    /// Its content hash.
    pub manifest_hash: ContentHash,
    /// Bulk sections.
    pub sections: Vec<BakedSection>,
    /// Per-stage report, in plan order.
    pub stages: Vec<StageReport>,
    /// Voxel grid and line-space figures, when baked.
    pub line_space: Option<LineSpaceStats>,
    /// Which sections the written file compresses.
    pub codec: crate::settings::Codec,
    /// Format, bytes and error of each texture, when textures were baked.
    pub textures: Vec<bc::TextureReport>,
}

/// Figures of the voxel grid and line space, for the report.
#[derive(Debug, Clone, Serialize)]
pub struct LineSpaceStats {
    /// Cells per axis.
    pub cells: [u32; 3],
    /// Non-empty cells.
    pub slots: u32,
    /// Shaft resolution.
    pub shaft_res: u32,
    /// Variants baked.
    pub variants: String,
    /// Filled shafts.
    pub filled_shafts: u64,
    /// Candidate entries.
    pub candidate_entries: u64,
    /// Triangles of the fullest cell.
    pub max_cell_triangles: u32,
    /// (Triangle, shaft) pairs left to the exact separating-axis decision: those no single
    /// separation rejects at both ends (counted even where the sign masks alone decide them; a
    /// triangle spanning its cell decides its shafts in closed form, uncounted).
    pub overlap_tests: u64,
    /// Filled shafts with a missing front or back PNMT record.
    pub pnmt_missing_records: u64,
    /// Bytes of the voxel grid (header, offsets, triangle lists).
    pub bytes_voxel_grid: u64,
    /// Bytes of the binary line space (slots, bits, ranks).
    pub bytes_binary: u64,
    /// Bytes of the candidate lists.
    pub bytes_candidates: u64,
    /// Bytes of the PNMT records.
    pub bytes_pnmt: u64,
    /// How the PNMT records are stored: `full`, `compact` or `compact-no-uv` (null without PNMT).
    pub pnmt_records: Option<&'static str>,
    /// Where the shafts were baked (`--line-space-device`): the GPU's name, or `cpu`; null when
    /// the stage came from the cache. The bytes are the same either way.
    pub device: Option<String>,
}

/// Hash of the inputs: the contents of every file read, in reading order, or the scene data
/// itself when it came from no file (the demo).
pub fn input_hash(scene: &Scene, inputs: &[InputFile]) -> ContentHash {
    let mut h = ContentHasher::new();
    h.part("algorithm", ALGORITHM_VERSION.as_bytes());
    if inputs.is_empty() {
        h.part("vertices", bytemuck::cast_slice(&scene.vertices));
        h.part("triangles", bytemuck::cast_slice(&scene.triangles));
        h.part(
            "materials",
            &scene.materials.iter().flat_map(|m| bytemuck::bytes_of(&m.gpu).to_vec()).collect::<Vec<u8>>(),
        );
        h.part(
            "lights",
            format!("{:?}{:?}{:?}{:?}", scene.lights, scene.cameras, scene.orthographic, scene.sky)
                .as_bytes(),
        );
    }
    for i in inputs {
        h.part("input", i.hash.as_bytes());
    }
    h.finish()
}

/// What a stage produces: its sections and the manifest records that describe them.
#[derive(Debug, Default)]
pub struct Sections {
    /// The sections.
    pub list: Vec<BakedSection>,
    /// The BRDF table's record.
    pub brdf_lut: Option<BrdfLutInfo>,
    /// The shadow maps' records, in section index order.
    pub shadow_maps: Vec<ShadowMapInfo>,
    /// The light-visibility volume's record.
    pub media_visibility: Option<MediaVisibilityInfo>,
}

impl Sections {
    /// Adds a section (its content hash is set by [`bake`] from the stage's key).
    pub fn push(&mut self, kind: SectionKind, index: u32, bytes: Vec<u8>) {
        self.list.push(BakedSection { kind, index, bytes, hash: ContentHash::default() });
    }

    /// The sections and records of a cache entry (private sections left out).
    fn from_entry(e: cache::Entry) -> Sections {
        let mut out = Sections {
            brdf_lut: e.manifest.brdf_lut,
            shadow_maps: e.manifest.shadow_maps,
            media_visibility: e.manifest.media_visibility,
            ..Default::default()
        };
        for s in e.sections {
            if kiln_format::sections::info(s.kind).is_some() {
                out.push(s.kind, s.index, s.bytes);
            }
        }
        out
    }

    /// The manifest of this stage's cache entry: its records, nothing else.
    fn records(&self) -> Manifest {
        Manifest {
            brdf_lut: self.brdf_lut,
            shadow_maps: self.shadow_maps.clone(),
            media_visibility: self.media_visibility.clone(),
            ..Default::default()
        }
    }

    /// The sections as a cache entry lists them.
    fn entry_sections(&self) -> Vec<(SectionKind, u32, &[u8])> {
        self.list.iter().map(|s| (s.kind, s.index, s.bytes.as_slice())).collect()
    }

    /// Moves `other`'s sections and records after these.
    pub fn append(&mut self, mut other: Sections) {
        self.list.append(&mut other.list);
        self.brdf_lut = self.brdf_lut.or(other.brdf_lut);
        self.shadow_maps.append(&mut other.shadow_maps);
        self.media_visibility = self.media_visibility.take().or(other.media_visibility);
    }

    /// Bytes of every section.
    pub fn bytes(&self) -> u64 {
        self.list.iter().map(|s| s.bytes.len() as u64).sum()
    }
}

/// Private section kind of the line-space cache entry: the overlap tests run and the PNMT
/// records missing (two `u64`), which the report shows.
const LINE_SPACE_COUNTS: SectionKind = SectionKind(*b"kLSC");

/// Section kinds of the voxel-grid stage (the rest of the line-space entry is the line space's).
const GRID_KINDS: [SectionKind; 3] = [
    kiln_format::sections::GRID,
    kiln_format::sections::VOXEL_OFFSETS,
    kiln_format::sections::VOXEL_TRIANGLES,
];

/// Lights and media as the manifest encodes them (exact: every field, bit for bit).
fn records_bytes(
    lights: &[kiln_format::manifest::Light],
    media: &[kiln_format::manifest::Medium],
) -> Vec<u8> {
    Manifest { lights: lights.to_vec(), media: media.to_vec(), ..Default::default() }.encode()
}

/// What shadow maps read of the lights: whether each casts shadows, its kind with its cone or
/// size, position and direction (bit for bit); not its colour, intensity or range, so that
/// re-colouring a light re-bakes no shadow map.
fn shadow_geometry(lights: &[kiln_format::manifest::Light]) -> Vec<u8> {
    use kiln_format::manifest::LightKind;
    let mut v = Vec::new();
    for l in lights {
        let (tag, a, b) = match l.kind {
            LightKind::Point => (0u8, 0.0, 0.0),
            LightKind::Spot { inner_cone, outer_cone } => (1, inner_cone, outer_cone),
            LightKind::Directional => (2, 0.0, 0.0),
            LightKind::Rect { width, height } => (3, width, height),
        };
        v.extend_from_slice(&[l.casts_shadows as u8, tag]);
        for x in [a, b].iter().chain(&l.position).chain(&l.direction) {
            v.extend_from_slice(&x.to_bits().to_le_bytes());
        }
    }
    v
}

/// Adds every texture's texels and sampling state (its name aside) to `h`.
fn hash_textures(h: &mut ContentHasher, scene: &Scene) {
    for t in &scene.textures {
        let state =
            format!("{}x{} {:?} {:?} {:?} {}", t.width, t.height, t.role, t.wrap_u, t.wrap_v, t.mag_linear);
        h.part("texture", state.as_bytes()).part("rgba", &t.rgba);
    }
}

/// The cache key of `stage`: the layout, compiler and algorithm versions, and exactly what the
/// stage reads (settings and data), so that a hit is never stale. The voxel grid and the line
/// space share one key (one bake makes both: the grid header holds the line space's figures).
pub fn stage_key(ctx: &BakeContext, stage: Stage) -> ContentHash {
    let (s, scene) = (ctx.settings, ctx.scene);
    let bounds =
        |b: &kiln_format::manifest::Bounds| -> Vec<u8> { bytemuck::cast_slice(&[b.min, b.max]).to_vec() };
    let mut h = match stage {
        Stage::VoxelGrid | Stage::LineSpace => cache::key("line-space"),
        _ => cache::key(stage.name()),
    };
    match stage {
        Stage::Geometry => {
            // The vertices, and the triangles and their materials in BVH leaf order.
            h.hash("geometry", &ctx.geometry_key)
                .part("triangle-materials", bytemuck::cast_slice(&ctx.triangle_materials));
        }
        Stage::Uvs => {
            h.part("uvs", bytemuck::cast_slice(&scene.uvs));
        }
        Stage::VertexColors => {
            h.part("colors", bytemuck::cast_slice(&scene.colors));
        }
        Stage::Materials => {
            h.part("materials", bytemuck::cast_slice(&ctx.materials));
            if materials::textured_emission(ctx) {
                // The emitted luminance per triangle: in stored order, through the uvs and textures.
                h.part("triangles", bytemuck::cast_slice(&ctx.triangles))
                    .part("triangle-materials", bytemuck::cast_slice(&ctx.triangle_materials))
                    .part("uvs", bytemuck::cast_slice(&scene.uvs));
                hash_textures(&mut h, scene);
            }
        }
        Stage::Textures => {
            // The format of each texture follows the setting and the material slots reading it.
            h.part("algorithm", textures::TEXTURE_ALGORITHM.as_bytes())
                .part("texture-format", s.texture_format.name().as_bytes());
            let usages: Vec<u8> =
                (0..scene.textures.len() as u32).map(|i| bc::Usage::of(&ctx.materials, i).bits()).collect();
            h.part("usages", &usages);
            hash_textures(&mut h, scene);
        }
        Stage::Bvh => {
            h.hash("bvh", &ctx.bvh_key);
        }
        Stage::BrdfLut => {
            h.part("res", &s.brdf_lut_res.to_le_bytes()).part("samples", &brdf_lut::SAMPLES.to_le_bytes());
        }
        Stage::ShadowMaps => {
            // Texel rays through the BVH from each caster's layout over the scene bounds.
            h.part("res", &s.shadow_res.to_le_bytes())
                .part("lights", &shadow_geometry(&scene.lights))
                .part("bounds", &bounds(&ctx.geometry.bounds))
                .hash("geometry", &ctx.geometry_key);
        }
        Stage::Environment => {
            if let Some(env) = &scene.environment {
                h.part("width", &env.width.to_le_bytes())
                    .part("pixels", bytemuck::cast_slice(&env.pixels))
                    .part("rotation", &env.rotation_degrees.to_le_bytes())
                    .part("res", &s.environment_res.to_le_bytes())
                    .part(
                        "filter",
                        format!(
                            "{} {} {} {}",
                            environment::LEVELS,
                            environment::FILTERED_WIDTH,
                            environment::TABLE_WIDTH,
                            environment::FILTER_SAMPLES
                        )
                        .as_bytes(),
                    );
            }
        }
        Stage::Probes => {
            // Paths through the stored geometry, shaded by the materials, textures, lights and
            // sky; the layout (spacing, dims, rays, regularisation) as the plan resolved it.
            let l = ctx.plan.probes.map(|l| {
                format!(
                    "{:?} {} {:?} {} {} {}",
                    l.origin.to_array(),
                    l.spacing.to_bits(),
                    l.dims,
                    l.layers,
                    l.rays,
                    l.min_roughness.to_bits()
                )
            });
            let lut = if ctx.plan.runs(Stage::BrdfLut) { s.brdf_lut_res } else { 0 };
            h.part("layout", l.unwrap_or_default().as_bytes())
                .hash("geometry", &ctx.geometry_key)
                .part("triangle-materials", bytemuck::cast_slice(&ctx.triangle_materials))
                .part("uvs", bytemuck::cast_slice(&scene.uvs))
                .part("materials", bytemuck::cast_slice(&ctx.materials))
                .part("lights", &records_bytes(&scene.lights, &[]))
                .part("sky", bytemuck::cast_slice(&scene.sky.radiance))
                .part("lut", &lut.to_le_bytes());
            if ctx.plan.runs(Stage::Environment) {
                h.hash("environment", &stage_key(ctx, Stage::Environment));
            }
            hash_textures(&mut h, scene);
        }
        Stage::MediaVisibility => {
            h.part("res", &s.media_volume_res.to_le_bytes())
                .part("lights-media", &records_bytes(&scene.lights, &scene.media))
                .part("sky", bytemuck::cast_slice(&scene.sky.radiance))
                .hash("geometry", &ctx.geometry_key);
            // The sky's volume weighs directions by the environment's light.
            if let Some(env) = &scene.environment {
                h.part("environment", bytemuck::cast_slice(&env.pixels))
                    .part("environment-rotation", &env.rotation_degrees.to_le_bytes());
            }
        }
        Stage::VoxelGrid | Stage::LineSpace => {
            // The grid over the corners in stored order; PNMT records read normals (in the
            // vertices), texture coordinates and materials; lights only through pre-illumination.
            let p = ctx.plan;
            h.part("voxel-res", &p.voxel_res.to_le_bytes())
                .part("shaft-res", &p.shaft_res.to_le_bytes())
                .part("variants", &p.shaft_variants.to_le_bytes())
                .part("bounds", &bounds(&ctx.geometry.bounds))
                .hash("geometry", &ctx.geometry_key)
                .part("triangle-materials", bytemuck::cast_slice(&ctx.triangle_materials))
                .part("uvs", bytemuck::cast_slice(&scene.uvs));
            // The records' layout only where records are baked (binary and candidates alone do
            // not depend on it).
            if p.shaft_variants
                & (kiln_format::linespace::Variants::PNMT | kiln_format::linespace::Variants::PREILLUM)
                != 0
            {
                h.part("pnmt-layout", &p.pnmt_layout.code().to_le_bytes());
            }
            if p.shaft_variants & kiln_format::linespace::Variants::PREILLUM != 0 {
                let lut = if p.runs(Stage::BrdfLut) { s.brdf_lut_res } else { 0 };
                h.part("lights", &records_bytes(&scene.lights, &[]))
                    .part("materials", bytemuck::cast_slice(&ctx.materials))
                    .part("lut", &lut.to_le_bytes());
                hash_textures(&mut h, scene);
            }
        }
    }
    h.finish()
}

/// The content hash of a section: its stage's key, kind and index (FORMAT.md: equal hashes mean
/// the section can be reused).
fn section_hash(key: &ContentHash, kind: SectionKind, index: u32) -> ContentHash {
    ContentHasher::new().hash("stage", key).part("kind", &kind.0).part("index", &index.to_le_bytes()).finish()
}

/// Loads `stage`'s entry under `key`; a damaged one is warned about and treated as a miss.
fn load(cache: &Cache, stage: &str, key: &ContentHash) -> Option<cache::Entry> {
    match cache.load(stage, key) {
        Ok(e) => e,
        Err(why) => {
            eprintln!("warning: stage cache: {why}; re-baking");
            None
        }
    }
}

/// Stores an entry; a failure is a warning (the compile's output does not depend on it).
fn store(
    cache: &Cache,
    stage: &str,
    key: &ContentHash,
    manifest: &Manifest,
    sections: &[(SectionKind, u32, &[u8])],
) {
    if let Err(e) = cache.store(stage, key, manifest, sections) {
        eprintln!("warning: stage cache: {e}");
    }
}

/// The output of one of the simple stages, from the cache when it holds it; whether it did.
fn cached_stage(ctx: &BakeContext, stage: Stage, key: &ContentHash) -> (Sections, bool) {
    let run = || match stage {
        Stage::Geometry => geometry::stage(ctx),
        Stage::Uvs => uvs::stage(ctx),
        Stage::VertexColors => uvs::colors(ctx),
        Stage::Materials => materials::stage(ctx),
        Stage::Textures => textures::stage(ctx),
        Stage::BrdfLut => brdf_lut::stage(ctx),
        Stage::ShadowMaps => shadow::stage(ctx),
        Stage::MediaVisibility => media::stage(ctx),
        Stage::Environment => environment::stage(ctx),
        Stage::Probes => probes::stage(ctx),
        // Made by the context (BVH) and by `grid_and_line_space`.
        Stage::Bvh | Stage::VoxelGrid | Stage::LineSpace => Sections::default(),
    };
    let Some(cache) = ctx.cache else { return (run(), false) };
    if let Some(e) = load(cache, stage.name(), key) {
        return (Sections::from_entry(e), true);
    }
    let out = run();
    store(cache, stage.name(), key, &out.records(), &out.entry_sections());
    (out, false)
}

/// The voxel grid's and the line space's sections, their figures, their times (ms) and whether
/// they came from the cache.
struct GridAndLineSpace {
    grid: Sections,
    line_space: Sections,
    stats: LineSpaceStats,
    grid_ms: f64,
    line_space_ms: f64,
    cached: bool,
}

/// Bakes (or loads) the voxel grid and the line space: one bake, one cache entry.
fn grid_and_line_space(ctx: &BakeContext, key: &ContentHash) -> CliResult<GridAndLineSpace> {
    let start = Instant::now();
    let split = |all: Vec<BakedSection>| -> (Sections, Sections) {
        let (grid, ls): (Vec<_>, Vec<_>) = all.into_iter().partition(|s| GRID_KINDS.contains(&s.kind));
        (Sections { list: grid, ..Default::default() }, Sections { list: ls, ..Default::default() })
    };
    if let Some(cache) = ctx.cache
        && let Some(mut e) = load(cache, "line-space", key)
    {
        let counts = e.take(LINE_SPACE_COUNTS, 0).filter(|c| c.len() == 16);
        let (grid, line_space) = split(Sections::from_entry(e).list);
        let stats = counts.and_then(|c| {
            let c: [u64; 2] = bytemuck::pod_read_unaligned(&c);
            LineSpaceStats::of_sections(&grid, &line_space, c[0], c[1])
        });
        match stats {
            Some(stats) => {
                let grid_ms = start.elapsed().as_secs_f64() * 1e3;
                return Ok(GridAndLineSpace {
                    grid,
                    line_space,
                    stats,
                    grid_ms,
                    line_space_ms: 0.0,
                    cached: true,
                });
            }
            None => eprintln!(
                "warning: stage cache: {}: no voxel grid header or counts; re-baking",
                cache.path("line-space", key).display()
            ),
        }
    }
    let (grid, baked) = linespace::stages::voxel_grid(ctx)?;
    let line_space = linespace::stages::line_space(&baked);
    let counts = [baked.tests, baked.pnmt_missing];
    let (grid_ms, line_space_ms) = (baked.voxel_ms, baked.total_ms - baked.voxel_ms);
    let device = baked.device.clone().unwrap_or_else(|| "cpu".into());
    drop(baked);
    let mut stats = LineSpaceStats::of_sections(&grid, &line_space, counts[0], counts[1])
        .ok_or_else(|| crate::exit::CliError::input("the voxel-grid stage made no grid header"))?;
    stats.device = Some(device);
    if let Some(cache) = ctx.cache {
        let mut sections = grid.entry_sections();
        sections.extend(line_space.entry_sections());
        sections.push((LINE_SPACE_COUNTS, 0, bytemuck::cast_slice(&counts)));
        store(cache, "line-space", key, &Manifest::default(), &sections);
    }
    Ok(GridAndLineSpace { grid, line_space, stats, grid_ms, line_space_ms, cached: false })
}

/// Runs every stage the plan allows, in plan order, over `ctx`, taking each stage's output from
/// the context's cache when it holds it (and storing it there when not).
pub fn bake(ctx: &BakeContext) -> CliResult<Baked> {
    let mut all = Sections::default();
    let mut stages: Vec<StageReport> = Vec::new();
    let mut line_space: Option<LineSpaceStats> = None;
    let mut texture_reports = Vec::new();
    // The line-space stage's sections and time, made with the grid's.
    let mut pending: Option<(Sections, f64, bool)> = None;
    for decision in &ctx.plan.stages {
        let start = Instant::now();
        let mut out = Sections::default();
        let mut cached = false;
        let mut ms = None;
        if decision.run {
            ctx.progress.stage(decision.stage.name());
            let key = stage_key(ctx, decision.stage);
            match decision.stage {
                // The BVH is built (or loaded) before every stage: the geometry is stored in its
                // leaf order.
                Stage::Bvh => {
                    out = bvh::stage(ctx);
                    (cached, ms) = (ctx.bvh_cached, Some(ctx.bvh_ms));
                }
                Stage::VoxelGrid => {
                    let g = grid_and_line_space(ctx, &key)?;
                    (out, cached, ms) = (g.grid, g.cached, Some(g.grid_ms));
                    line_space = Some(g.stats);
                    pending = Some((g.line_space, g.line_space_ms, g.cached));
                }
                Stage::LineSpace => {
                    if let Some((ls, ls_ms, ls_cached)) = pending.take() {
                        (out, ms, cached) = (ls, Some(ls_ms), ls_cached);
                    }
                }
                stage => (out, cached) = cached_stage(ctx, stage, &key),
            }
            for s in &mut out.list {
                s.hash = section_hash(&key, s.kind, s.index);
            }
        }
        let ms = ms.unwrap_or_else(|| start.elapsed().as_secs_f64() * 1e3);
        if decision.run && decision.stage == Stage::Textures {
            // Measured after the stage's time is taken: the report's error figures are not part
            // of what the texture stage costs a compile without them.
            texture_reports = textures::reports(ctx, &out);
        }
        stages.push(StageReport {
            stage: decision.stage.name(),
            run: decision.run,
            cached,
            reason: decision.reason.clone(),
            ms,
            bytes: out.bytes(),
        });
        all.append(out);
    }
    let (manifest, manifest_hash) = assemble_manifest(ctx, &all);
    Ok(Baked {
        manifest,
        manifest_hash,
        sections: all.list,
        stages,
        line_space,
        codec: ctx.settings.codec,
        textures: texture_reports,
    })
}

/// The manifest and its content hash.
fn assemble_manifest(ctx: &BakeContext, all: &Sections) -> (Manifest, ContentHash) {
    let scene = ctx.scene;
    let manifest = Manifest {
        generator: format!("kiln {}", env!("CARGO_PKG_VERSION")),
        scene_name: scene.name.clone(),
        inputs: ctx.inputs.clone(),
        settings: ctx.settings.pairs().into_iter().map(|(key, value)| Setting { key, value }).collect(),
        bounds: ctx.geometry.bounds,
        materials: scene.materials.iter().map(|m| MaterialInfo { name: m.name.clone() }).collect(),
        textures: scene
            .textures
            .iter()
            .map(|t| TextureInfo {
                name: t.name.clone(),
                width: t.width,
                height: t.height,
                mip_levels: kiln_format::scene::mip_levels(t.width, t.height),
                color_space: t.role.color_space(),
                wrap_u: t.wrap_u,
                wrap_v: t.wrap_v,
                mag_linear: t.mag_linear,
            })
            .collect(),
        lights: scene.lights.clone(),
        cameras: scene.cameras.clone(),
        orthographic: scene.orthographic.clone(),
        origin: scene.origin,
        // With an environment, the constant sky is its mean: what a reader that ignores the
        // environment's sections shows.
        sky: ctx.environment().map_or(scene.sky, |e| kiln_format::manifest::Sky { radiance: e.mean }),
        media: scene.media.clone(),
        skipped: ctx
            .plan
            .stages
            .iter()
            .filter(|d| !d.run)
            .map(|d| SkippedStage { stage: d.stage.name().into(), reason: d.reason.clone() })
            .collect(),
        degenerate_triangles: scene.degenerate_triangles,
        brdf_lut: all.brdf_lut,
        shadow_maps: all.shadow_maps.clone(),
        media_visibility: all.media_visibility.clone(),
    };
    let settings_text: String = ctx.settings.pairs().iter().map(|(k, v)| format!("{k}={v};")).collect();
    (manifest, ctx.hash("manifest", &[("settings", &settings_text)]))
}

impl LineSpaceStats {
    /// The figures of the voxel grid's and line space's sections (the grid header holds the
    /// counts), with the overlap tests run and the PNMT records missing; `None` without a header.
    fn of_sections(grid: &Sections, ls: &Sections, tests: u64, pnmt_missing: u64) -> Option<LineSpaceStats> {
        use kiln_format::sections as k;
        let bytes = |kinds: &[SectionKind]| -> u64 {
            grid.list
                .iter()
                .chain(&ls.list)
                .filter(|s| kinds.contains(&s.kind))
                .map(|s| s.bytes.len() as u64)
                .sum()
        };
        let header_bytes = grid.list.iter().find(|s| s.kind == k::GRID)?;
        let header: kiln_format::linespace::GridHeader =
            bytemuck::try_pod_read_unaligned(&header_bytes.bytes).ok()?;
        Some(LineSpaceStats {
            cells: header.dims,
            slots: header.slots,
            shaft_res: header.shaft_res,
            variants: crate::settings::variants_name(header.variants),
            filled_shafts: header.filled,
            candidate_entries: header.entries,
            max_cell_triangles: header.max_cell_triangles,
            overlap_tests: tests,
            pnmt_missing_records: pnmt_missing,
            bytes_voxel_grid: bytes(&GRID_KINDS),
            bytes_binary: bytes(&[k::SHAFT_SLOTS, k::SHAFT_BITS, k::SHAFT_RANKS]),
            bytes_candidates: bytes(&[k::CANDIDATE_OFFSETS, k::CANDIDATES]),
            bytes_pnmt: bytes(&[k::PNMT]),
            pnmt_records: (header.variants & kiln_format::linespace::Variants::PNMT != 0)
                .then(|| header.pnmt_records().map(|l| l.name()))
                .flatten(),
            device: None,
        })
    }
}

fn writer(baked: &Baked, threads: usize) -> Result<kiln_format::FileWriter<'_>, kiln_format::WriteError> {
    let mut w = kiln_format::FileWriter::new();
    w.compression(baked.codec.compression()).threads(threads);
    w.manifest(&baked.manifest, baked.manifest_hash)?;
    // Full PNMT records (or none) are what version 1 of VGRD and LSPN hold, byte for byte: written
    // at version 1, such a file stays readable by format 1.2 readers. Compact ones need version 2.
    let full = baked
        .sections
        .iter()
        .find(|s| s.kind == kiln_format::sections::GRID)
        .and_then(|s| bytemuck::try_pod_read_unaligned::<kiln_format::linespace::GridHeader>(&s.bytes).ok())
        .is_some_and(|h| h.pnmt_layout == kiln_format::linespace::PnmtLayout::Full.code());
    for s in &baked.sections {
        if full && [kiln_format::sections::GRID, kiln_format::sections::PNMT].contains(&s.kind) {
            w.raw(s.kind, s.index, 1, s.bytes.as_slice(), s.hash)?;
        } else {
            w.bytes(s.kind, s.index, s.bytes.as_slice(), s.hash)?;
        }
    }
    Ok(w)
}

/// Writes the baked file atomically, compressing on `threads` threads; returns its size.
pub fn write(baked: &Baked, path: &std::path::Path, threads: usize) -> Result<u64, kiln_format::WriteError> {
    writer(baked, threads)?.write_atomic(path)
}

/// The baked file in memory, compressed on the current rayon pool's thread count.
pub fn to_bytes(baked: &Baked) -> Result<Vec<u8>, kiln_format::WriteError> {
    writer(baked, rayon::current_num_threads())?.to_bytes()
}
