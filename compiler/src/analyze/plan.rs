//! The bake plan: every stage with *run* or *skip* and the reason, decided from the scene and
//! settings alone, before any bake work.

use serde::Serialize;

use crate::ir::Scene;
use crate::settings::Settings;

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
        }
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
}

impl Plan {
    /// Decides every stage.
    pub fn new(scene: &Scene, settings: &Settings) -> Plan {
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
        Plan { stages }
    }

    /// Whether `stage` runs.
    pub fn runs(&self, stage: Stage) -> bool {
        self.stages.iter().any(|d| d.stage == stage && d.run)
    }
}
