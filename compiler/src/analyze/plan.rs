//! The bake plan: every stage with *run* or *skip* and the reason, decided from the scene and
//! settings alone, before any bake work.

use serde::Serialize;

use crate::ir::Scene;
use kiln_format::linespace::Variants;
use kiln_format::manifest::LightKind;

use crate::analyze::geometry::SceneGeometry;
use crate::bake::linespace::voxelize::auto_resolution;
use crate::settings::{Settings, VoxelRes, variants_name};

/// The bake stages, in the order they run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stage {
    /// Vertices, triangles (in BVH order) and per-triangle materials.
    Geometry,
    /// Texture coordinates.
    Uvs,
    /// Material table.
    Materials,
    /// Texture mip chains.
    Textures,
    /// The compressed wide BVH.
    Bvh,
    /// The split-sum BRDF table.
    BrdfLut,
    /// Shadow maps of the shadow-casting lights.
    ShadowMaps,
    /// Light-visibility volume of the participating medium.
    MediaVisibility,
    /// Cell triangle lists of the voxel grid.
    VoxelGrid,
    /// Shafts per non-empty cell: binary, candidates, PNMT.
    LineSpace,
}

impl Stage {
    /// Name as printed by `kiln plan` and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Geometry => "geometry",
            Stage::Uvs => "uvs",
            Stage::Materials => "materials",
            Stage::Textures => "textures",
            Stage::Bvh => "bvh",
            Stage::BrdfLut => "brdf-lut",
            Stage::ShadowMaps => "shadow-maps",
            Stage::MediaVisibility => "media-visibility",
            Stage::VoxelGrid => "voxel-grid",
            Stage::LineSpace => "line-space",
        }
    }
}

/// Size budget of the line space chosen by default (variants are dropped, most expensive
/// first, until the estimate fits); `--shaft-variants` overrides it.
pub const DEFAULT_LINE_SPACE_BUDGET: u64 = 384 << 20;

/// Default variants for a lit scene: all three, unless the estimated size exceeds
/// [`DEFAULT_LINE_SPACE_BUDGET`]. The estimate counts the non-empty cells of the voxel grid
/// (which the bake then reuses) and assumes 70% of their shafts filled with 5 candidate entries each, as measured on the benchmark
/// and shared scenes.
fn default_variants(geometry: &SceneGeometry, res: u32, n: u32) -> (u32, String) {
    let slots = geometry.voxels(res).occupied_cells() as u64;
    let filled = slots * kiln_format::linespace::index::shafts_per_voxel(n) as u64 * 7 / 10;
    let pnmt = filled * 32;
    let candidates = filled * (4 + 5 * 4);
    let mib = |b: u64| b >> 20;
    let budget = DEFAULT_LINE_SPACE_BUDGET;
    if pnmt + candidates <= budget {
        (Variants::DEFAULT, format!("all variants: the scene is lit; about {} MiB", mib(pnmt + candidates)))
    } else if pnmt <= budget {
        (
            Variants::BINARY | Variants::PNMT,
            format!(
                "candidate lists skipped: with PNMT about {} MiB, over the {} MiB default budget",
                mib(pnmt + candidates),
                mib(budget)
            ),
        )
    } else {
        (
            Variants::BINARY,
            format!(
                "PNMT and candidates skipped: about {} MiB, over the {} MiB default budget",
                mib(pnmt + candidates),
                mib(budget)
            ),
        )
    }
}

/// One stage's decision.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Decision {
    /// Stage.
    pub stage: Stage,
    /// Whether it runs.
    pub run: bool,
    /// Why (for runs: what it will produce).
    pub reason: String,
}

/// The plan for a scene.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Plan {
    /// Every stage, in order.
    pub stages: Vec<Decision>,
    /// Voxel grid cells along the longest axis (resolved from `auto`).
    pub voxel_res: u32,
    /// Line-space variants to bake (0: none).
    pub shaft_variants: u32,
}

impl Plan {
    /// Decides every stage; `geometry` is `scene`'s (its voxel grid is built here when the
    /// default variants need a size estimate, and reused by the bake).
    pub fn new(scene: &Scene, geometry: &SceneGeometry, settings: &Settings) -> Plan {
        let run = |stage, reason: String| Decision { stage, run: true, reason };
        let skip = |stage, reason: &str| Decision { stage, run: false, reason: reason.to_string() };
        let textured =
            scene.materials.iter().filter(|m| m.gpu.textures().iter().any(|&t| t != u32::MAX)).count();
        let stages = vec![
            run(
                Stage::Geometry,
                format!("{} triangles, {} vertices", scene.triangles.len(), scene.vertices.len()),
            ),
            if textured > 0 {
                run(Stage::Uvs, format!("{textured} materials sample textures"))
            } else {
                skip(Stage::Uvs, "no material samples a texture")
            },
            run(Stage::Materials, format!("{} materials", scene.materials.len())),
            if scene.textures.is_empty() {
                skip(Stage::Textures, "the scene has no textures")
            } else {
                run(Stage::Textures, format!("{} textures with full mip chains", scene.textures.len()))
            },
            run(Stage::Bvh, format!("CWBVH, preset {}", settings.bvh_preset.name())),
        ];
        let mut stages = stages;
        let specular = scene
            .materials
            .iter()
            .filter(|m| m.gpu.flags & kiln_format::sections::MaterialFlags::DIFFUSE_ONLY == 0)
            .count();
        stages.push(if specular == 0 {
            skip(Stage::BrdfLut, "every material is pure Lambertian: no specular lobe to pre-integrate")
        } else {
            run(
                Stage::BrdfLut,
                format!(
                    "{0}x{0} texels for {specular} materials with a specular lobe",
                    settings.brdf_lut_res
                ),
            )
        });
        let casters = scene.lights.iter().filter(|l| l.casts_shadows).count();
        stages.push(if scene.lights.is_empty() {
            skip(Stage::ShadowMaps, "the scene has no analytic lights")
        } else if casters == 0 {
            skip(Stage::ShadowMaps, "no light casts shadows")
        } else {
            let cubes = scene
                .lights
                .iter()
                .filter(|l| l.casts_shadows && matches!(l.kind, LightKind::Point | LightKind::Rect { .. }))
                .count();
            run(
                Stage::ShadowMaps,
                format!(
                    "{} maps of {1}x{1}, {cubes} cube maps of 6x{2}x{2}",
                    casters - cubes,
                    settings.shadow_res,
                    (settings.shadow_res / 2).max(1)
                ),
            )
        });
        stages.push(if scene.media.is_empty() {
            skip(Stage::MediaVisibility, "the scene has no participating medium")
        } else if casters == 0 {
            skip(Stage::MediaVisibility, "no light casts shadows: every cell sees every light")
        } else {
            run(
                Stage::MediaVisibility,
                format!(
                    "medium 0, {casters} lights, {} cells on the longest axis",
                    settings.media_volume_res
                ),
            )
        });
        let voxel_res = match settings.voxel_res {
            VoxelRes::Auto => auto_resolution(scene.triangles.len()),
            VoxelRes::Cells(n) => n,
        };
        let lit = !scene.lights.is_empty()
            || scene.materials.iter().any(|m| m.gpu.emission.iter().any(|&e| e > 0.0))
            || scene.sky.radiance.iter().any(|&r| r > 0.0);
        let res_text = match settings.voxel_res {
            VoxelRes::Auto => format!(
                "{voxel_res} cells on the longest axis (auto: cube root of {} triangles)",
                scene.triangles.len()
            ),
            VoxelRes::Cells(n) => format!("{n} cells on the longest axis"),
        };
        let (shaft_variants, chosen) = match settings.shaft_variants {
            Some(v) => (v, "requested".to_string()),
            None if lit => default_variants(geometry, voxel_res, settings.shaft_res),
            None => (0, String::new()),
        };
        if shaft_variants == 0 {
            let why = if settings.shaft_variants.is_some() {
                "disabled by --shaft-variants none"
            } else {
                "nothing emits light, so no shadow or GI query needs it (ask with --shaft-variants)"
            };
            stages.push(skip(Stage::VoxelGrid, why));
            stages.push(skip(Stage::LineSpace, why));
        } else {
            stages.push(run(Stage::VoxelGrid, res_text));
            stages.push(run(
                Stage::LineSpace,
                format!(
                    "N = {}, {} ({chosen})",
                    settings.shaft_res,
                    variants_name(shaft_variants | Variants::BINARY)
                ),
            ));
        }
        Plan { stages, voxel_res, shaft_variants }
    }

    /// Whether `stage` runs.
    pub fn runs(&self, stage: Stage) -> bool {
        self.stages.iter().any(|d| d.stage == stage && d.run)
    }
}
