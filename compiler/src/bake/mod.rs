//! Bake stages: each a function of the [`BakeContext`] producing [`Sections`], one per file,
//! timed, with content hashes computed from what they depend on. [`bake`] runs the plan's stages
//! in order and assembles the manifest.

pub mod brdf_lut;
pub mod bvh;
pub mod context;
pub mod geometry;
pub mod linespace;
pub mod materials;
pub mod media;
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
use crate::exit::CliResult;
use crate::ir::Scene;

/// Bumped when a stage's algorithm changes its output, so that caches keyed by content hashes
/// do not reuse stale sections. 2: CWBVH planes widened past f32 rounding; the voxel grid padded
/// by four of its own margins.
pub(crate) const ALGORITHM_VERSION: &str = "kiln-bake-2";

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
    /// Shaft–triangle overlap tests run by the hierarchical search.
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
        h.part("lights", format!("{:?}{:?}{:?}", scene.lights, scene.cameras, scene.sky).as_bytes());
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
    /// Adds a section.
    pub fn push(&mut self, kind: SectionKind, index: u32, bytes: Vec<u8>, hash: ContentHash) {
        self.list.push(BakedSection { kind, index, bytes, hash });
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

/// Runs every stage the plan allows, in plan order, over `ctx`.
pub fn bake(ctx: &BakeContext) -> CliResult<Baked> {
    let mut all = Sections::default();
    let mut stages: Vec<StageReport> = Vec::new();
    let mut line_space: Option<linespace::BakedLineSpace> = None;
    for decision in &ctx.plan.stages {
        let start = Instant::now();
        let mut out = Sections::default();
        if decision.run {
            ctx.progress.stage(decision.stage.name());
            out = match decision.stage {
                Stage::Geometry => geometry::stage(ctx),
                Stage::Uvs => uvs::stage(ctx),
                Stage::VertexColors => uvs::colors(ctx),
                Stage::Materials => materials::stage(ctx),
                Stage::Textures => textures::stage(ctx),
                Stage::Bvh => bvh::stage(ctx),
                Stage::BrdfLut => brdf_lut::stage(ctx),
                Stage::ShadowMaps => shadow::stage(ctx),
                Stage::MediaVisibility => media::stage(ctx),
                Stage::VoxelGrid => {
                    let (out, baked) = linespace::stages::voxel_grid(ctx)?;
                    line_space = Some(baked);
                    out
                }
                Stage::LineSpace => line_space
                    .as_ref()
                    .map_or_else(Sections::default, |ls| linespace::stages::line_space(ctx, ls)),
            };
        }
        // The BVH is built before every stage (the geometry is stored in its leaf order), and the
        // voxel-grid stage bakes the line space too (the grid header holds its figures).
        let ms = match decision.stage {
            Stage::Bvh => ctx.bvh_ms,
            Stage::VoxelGrid => line_space.as_ref().map_or(0.0, |l| l.voxel_ms),
            Stage::LineSpace => {
                let grid_ms = stages.iter().find(|s| s.stage == "voxel-grid").map_or(0.0, |s| s.ms);
                line_space.as_ref().map_or(0.0, |l| l.total_ms - grid_ms)
            }
            _ => start.elapsed().as_secs_f64() * 1e3,
        };
        stages.push(StageReport {
            stage: decision.stage.name(),
            run: decision.run,
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
        line_space: line_space.as_ref().map(LineSpaceStats::of),
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
        sky: scene.sky,
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
    fn of(l: &linespace::BakedLineSpace) -> LineSpaceStats {
        LineSpaceStats {
            cells: l.header.dims,
            slots: l.header.slots,
            shaft_res: l.header.shaft_res,
            variants: crate::settings::variants_name(l.header.variants),
            filled_shafts: l.header.filled,
            candidate_entries: l.header.entries,
            max_cell_triangles: l.header.max_cell_triangles,
            overlap_tests: l.tests,
            pnmt_missing_records: l.pnmt_missing,
            bytes_voxel_grid: 96 + 4 * (l.voxel_offsets.len() + l.voxel_triangles.len()) as u64,
            bytes_binary: 4 * (l.slots.len() + l.bits.len() + l.ranks.len()) as u64,
            bytes_candidates: 4 * (l.candidate_offsets.len() + l.candidates.len()) as u64,
            bytes_pnmt: 16 * l.pnmt.len() as u64,
        }
    }
}

fn writer(baked: &Baked) -> Result<kiln_format::FileWriter<'_>, kiln_format::WriteError> {
    let mut w = kiln_format::FileWriter::new();
    w.manifest(&baked.manifest, baked.manifest_hash)?;
    for s in &baked.sections {
        w.bytes(s.kind, s.index, s.bytes.as_slice(), s.hash)?;
    }
    Ok(w)
}

/// Writes the baked file atomically; returns its size.
pub fn write(baked: &Baked, path: &std::path::Path) -> Result<u64, kiln_format::WriteError> {
    writer(baked)?.write_atomic(path)
}

/// The baked file in memory.
pub fn to_bytes(baked: &Baked) -> Result<Vec<u8>, kiln_format::WriteError> {
    writer(baked)?.to_bytes()
}
