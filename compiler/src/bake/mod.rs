//! Bake stages: each a function of (scene, settings) producing sections, timed, with a content
//! hash computed from what it depends on.

pub mod brdf_lut;
pub mod bvh;
pub mod linespace;
pub mod media;
pub mod shadow;
pub mod textures;

use std::time::Instant;

use kiln_format::manifest::{
    BrdfLutInfo, InputFile, Manifest, MaterialInfo, Setting, SkippedStage, TextureInfo,
};
use kiln_format::sections::{self, GpuMaterial};
use kiln_format::{ContentHash, ContentHasher, SectionKind};
use rayon::prelude::*;
use serde::Serialize;

use crate::analyze::plan::{Plan, Stage};
use crate::analyze::validate::bounds;
use crate::exit::CliResult;
use crate::ir::Scene;
use crate::progress::Progress;
use crate::settings::Settings;

/// Bumped when a stage's algorithm changes its output, so that caches keyed by content hashes
/// do not reuse stale sections.
const ALGORITHM_VERSION: &str = "kiln-bake-1";

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

/// Runs every stage the plan allows.
pub fn bake(
    scene: &Scene,
    settings: &Settings,
    plan: &Plan,
    inputs: Vec<InputFile>,
    progress: &Progress,
) -> CliResult<Baked> {
    let root = input_hash(scene, &inputs);
    let hash = |label: &str, extra: &[(&str, &str)]| {
        let mut h = ContentHasher::new();
        h.hash("inputs", &root).part("stage", label.as_bytes());
        for (k, v) in extra {
            h.part(k, v.as_bytes());
        }
        h.finish()
    };
    let preset = settings.bvh_preset.name();
    let mut sections: Vec<BakedSection> = Vec::new();
    let mut stages = Vec::new();
    let mut push =
        |kind, index, bytes: Vec<u8>, hash| sections.push(BakedSection { kind, index, bytes, hash });

    // BVH first: the geometry is stored in its leaf order.
    let t0 = Instant::now();
    progress.stage("bvh");
    let tris = bvh::triangles(scene.triangles.iter().map(|t| t.map(|i| scene.vertices[i as usize].position)));
    let built = bvh::build(&tris, settings.bvh_preset)?;
    let bvh_bytes = bytemuck::cast_slice(&built.nodes).to_vec();
    let bvh_ms = t0.elapsed().as_secs_f64() * 1e3;
    let bvh_len = bvh_bytes.len() as u64;
    push(sections::BVH_NODES, 0, bvh_bytes, hash("bvh", &[("preset", preset)]));
    let tris: Vec<[u32; 3]> = built.order.iter().map(|&i| scene.triangles[i as usize]).collect();
    let tmat: Vec<u32> = built.order.iter().map(|&i| scene.triangle_materials[i as usize]).collect();
    let grid_settings = format!("{};{};{}", plan.voxel_res, settings.shaft_res, plan.shaft_variants);
    let mut line_space: Option<linespace::BakedLineSpace> = None;
    let mut lut: Vec<[u16; 2]> = Vec::new();
    let mut brdf_info = None;
    let mut shadow_infos = Vec::new();
    let mut media_info = None;
    let gpu_materials: Vec<GpuMaterial> = scene.materials.iter().map(|m| m.gpu).collect();
    let scene_bounds = bounds(scene);

    for decision in &plan.stages {
        let start = Instant::now();
        let mut bytes = 0u64;
        if decision.run {
            progress.stage(decision.stage.name());
            match decision.stage {
                Stage::Geometry => {
                    let tris: Vec<[u32; 3]> =
                        built.order.iter().map(|&i| scene.triangles[i as usize]).collect();
                    let tmat: Vec<u32> =
                        built.order.iter().map(|&i| scene.triangle_materials[i as usize]).collect();
                    let v = bytemuck::cast_slice(&scene.vertices).to_vec();
                    let t = bytemuck::cast_slice(&tris).to_vec();
                    let m = bytemuck::cast_slice(&tmat).to_vec();
                    bytes = (v.len() + t.len() + m.len()) as u64;
                    push(sections::VERTICES, 0, v, hash("vertices", &[]));
                    push(sections::TRIANGLES, 0, t, hash("triangles", &[("preset", preset)]));
                    push(
                        sections::TRIANGLE_MATERIALS,
                        0,
                        m,
                        hash("triangle-materials", &[("preset", preset)]),
                    );
                }
                Stage::Uvs => {
                    let b = bytemuck::cast_slice(&scene.uvs).to_vec();
                    bytes = b.len() as u64;
                    push(sections::UVS, 0, b, hash("uvs", &[]));
                }
                Stage::Materials => {
                    let mats: Vec<GpuMaterial> = scene.materials.iter().map(|m| m.gpu).collect();
                    let b = bytemuck::cast_slice(&mats).to_vec();
                    bytes = b.len() as u64;
                    push(sections::MATERIALS, 0, b, hash("materials", &[]));
                }
                Stage::Textures => {
                    let chains: Vec<Vec<u8>> = scene.textures.par_iter().map(textures::mip_chain).collect();
                    for (i, chain) in chains.into_iter().enumerate() {
                        bytes += chain.len() as u64;
                        push(
                            sections::TEXTURE,
                            i as u32,
                            chain,
                            hash("texture", &[("index", &i.to_string())]),
                        );
                    }
                }
                Stage::Bvh => bytes = bvh_len,
                Stage::BrdfLut => {
                    lut = brdf_lut::bake(settings.brdf_lut_res, brdf_lut::SAMPLES);
                    let b = bytemuck::cast_slice(&lut).to_vec();
                    bytes = b.len() as u64;
                    let h = ContentHasher::new()
                        .part("stage", b"brdf-lut")
                        .part("algorithm", ALGORITHM_VERSION.as_bytes())
                        .part("res", &settings.brdf_lut_res.to_le_bytes())
                        .part("samples", &brdf_lut::SAMPLES.to_le_bytes())
                        .finish();
                    push(sections::BRDF_LUT, 0, b, h);
                    brdf_info =
                        Some(BrdfLutInfo { resolution: settings.brdf_lut_res, samples: brdf_lut::SAMPLES });
                }
                Stage::ShadowMaps => {
                    let t =
                        kiln_format::query::IndexedTriangles { vertices: &scene.vertices, triangles: &tris };
                    for (i, light) in scene.lights.iter().enumerate() {
                        let Some(layout) =
                            shadow::layout(light, i as u32, &scene_bounds, settings.shadow_res)
                        else {
                            continue;
                        };
                        progress.stage(&format!("shadow map of light {i}"));
                        let depths = shadow::render(&layout, &built.nodes, &t);
                        let b = bytemuck::cast_slice(&depths).to_vec();
                        bytes += b.len() as u64;
                        let index = shadow_infos.len() as u32;
                        push(
                            sections::SHADOW_MAP,
                            index,
                            b,
                            hash(
                                "shadow-map",
                                &[("preset", preset), ("light", &format!("{i}:{}", settings.shadow_res))],
                            ),
                        );
                        shadow_infos.push(layout.info);
                    }
                }
                Stage::MediaVisibility => {
                    let shading = shading_scene(
                        scene,
                        &gpu_materials,
                        &built.nodes,
                        &tris,
                        &lut,
                        settings.brdf_lut_res,
                    );
                    let (info, volumes) = media::bake(&shading, &scene.media, 0, settings.media_volume_res);
                    for (i, v) in volumes.into_iter().enumerate() {
                        bytes += v.len() as u64;
                        push(
                            sections::MEDIA_VISIBILITY,
                            i as u32,
                            v,
                            hash(
                                "media-visibility",
                                &[("res", &settings.media_volume_res.to_string()), ("index", &i.to_string())],
                            ),
                        );
                    }
                    media_info = Some(info);
                }
                Stage::VoxelGrid => {
                    let shading = shading_scene(
                        scene,
                        &gpu_materials,
                        &built.nodes,
                        &tris,
                        &lut,
                        settings.brdf_lut_res,
                    );
                    let shade = |p: glam::DVec3, n: glam::Vec3, v: glam::Vec3, m: u16, uv: glam::Vec2| {
                        shading.radiance(p.as_vec3(), n, n, v, m as u32, uv)
                    };
                    let attrs = linespace::SceneAttributes {
                        vertices: &scene.vertices,
                        uvs: &scene.uvs,
                        triangles: &tris,
                        materials: &tmat,
                    };
                    let ls = linespace::bake(
                        &attrs,
                        &bounds(scene),
                        plan.voxel_res,
                        settings.shaft_res,
                        plan.shaft_variants,
                        Some(&shade),
                        progress,
                    )?;
                    let h = hash("voxel-grid", &[("preset", preset), ("grid", &grid_settings)]);
                    let header = bytemuck::bytes_of(&ls.header).to_vec();
                    let offsets = bytemuck::cast_slice(&ls.voxel_offsets).to_vec();
                    let cells = bytemuck::cast_slice(&ls.voxel_triangles).to_vec();
                    bytes = (header.len() + offsets.len() + cells.len()) as u64;
                    push(sections::GRID, 0, header, h);
                    push(sections::VOXEL_OFFSETS, 0, offsets, h);
                    push(sections::VOXEL_TRIANGLES, 0, cells, h);
                    line_space = Some(ls);
                }
                Stage::LineSpace => {
                    if let Some(ls) = &line_space {
                        let h = hash("line-space", &[("preset", preset), ("grid", &grid_settings)]);
                        let mut add = |kind, data: &[u8]| {
                            bytes += data.len() as u64;
                            push(kind, 0, data.to_vec(), h);
                        };
                        add(sections::SHAFT_SLOTS, bytemuck::cast_slice(&ls.slots));
                        add(sections::SHAFT_BITS, bytemuck::cast_slice(&ls.bits));
                        add(sections::SHAFT_RANKS, bytemuck::cast_slice(&ls.ranks));
                        if ls.header.variants & kiln_format::linespace::Variants::CANDIDATES != 0 {
                            add(sections::CANDIDATE_OFFSETS, bytemuck::cast_slice(&ls.candidate_offsets));
                            add(sections::CANDIDATES, bytemuck::cast_slice(&ls.candidates));
                        }
                        if ls.header.variants & kiln_format::linespace::Variants::PNMT != 0 {
                            add(sections::PNMT, bytemuck::cast_slice(&ls.pnmt));
                        }
                        if ls.header.variants & kiln_format::linespace::Variants::PREILLUM != 0 {
                            add(sections::PREILLUM, bytemuck::cast_slice(&ls.preillum));
                        }
                    }
                }
            }
        }
        let ms = match decision.stage {
            Stage::Bvh => bvh_ms,
            Stage::VoxelGrid => line_space.as_ref().map_or(0.0, |l| l.voxel_ms),
            Stage::LineSpace => {
                let grid_ms =
                    stages.iter().find(|s: &&StageReport| s.stage == "voxel-grid").map_or(0.0, |s| s.ms);
                line_space.as_ref().map_or(0.0, |l| l.total_ms - grid_ms)
            }
            _ => start.elapsed().as_secs_f64() * 1e3,
        };
        stages.push(StageReport {
            stage: decision.stage.name(),
            run: decision.run,
            reason: decision.reason.clone(),
            ms,
            bytes,
        });
    }

    let manifest = Manifest {
        generator: format!("kiln {}", env!("CARGO_PKG_VERSION")),
        scene_name: scene.name.clone(),
        inputs,
        settings: settings.pairs().into_iter().map(|(key, value)| Setting { key, value }).collect(),
        bounds: bounds(scene),
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
        skipped: plan
            .stages
            .iter()
            .filter(|d| !d.run)
            .map(|d| SkippedStage { stage: d.stage.name().into(), reason: d.reason.clone() })
            .collect(),
        degenerate_triangles: scene.degenerate_triangles,
        brdf_lut: brdf_info,
        shadow_maps: shadow_infos,
        media_visibility: media_info,
    };
    let settings_text: String = settings.pairs().iter().map(|(k, v)| format!("{k}={v};")).collect();
    let manifest_hash = hash("manifest", &[("settings", &settings_text)]);
    let line_space = line_space.map(|l| LineSpaceStats {
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
    });
    Ok(Baked { manifest, manifest_hash, sections, stages, line_space })
}

fn writer(baked: &Baked) -> Result<kiln_format::FileWriter<'_>, kiln_format::WriteError> {
    let mut w = kiln_format::FileWriter::new();
    w.manifest(&baked.manifest, baked.manifest_hash)?;
    for s in &baked.sections {
        w.bytes(s.kind, s.index, s.bytes.as_slice(), s.hash)?;
    }
    Ok(w)
}

/// The shading view of a scene whose triangles are stored in `tris` order.
fn shading_scene<'a>(
    scene: &'a Scene,
    materials: &'a [GpuMaterial],
    bvh: &'a [kiln_format::sections::CwbvhNode],
    tris: &'a [[u32; 3]],
    lut: &'a [[u16; 2]],
    lut_res: u32,
) -> crate::shading::ShadingScene<'a> {
    crate::shading::ShadingScene {
        materials,
        textures: &scene.textures,
        lights: &scene.lights,
        bvh,
        vertices: &scene.vertices,
        triangles: tris,
        lut,
        lut_res,
    }
}

/// Writes the baked file atomically; returns its size.
pub fn write(baked: &Baked, path: &std::path::Path) -> Result<u64, kiln_format::WriteError> {
    writer(baked)?.write_atomic(path)
}

/// The baked file in memory.
pub fn to_bytes(baked: &Baked) -> Result<Vec<u8>, kiln_format::WriteError> {
    writer(baked)?.to_bytes()
}
