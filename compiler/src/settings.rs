//! Bake settings: what the command line and the sidecar's `[bake]` table decide.

use clap::ValueEnum;
use kiln_format::linespace::Variants;

/// BVH build effort (obvhs presets; none uses spatial splits, so every triangle lies in exactly
/// one leaf and triangles can be stored in leaf order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum BvhPreset {
    /// PLOC with a short search radius, little reinsertion: fastest build.
    Fast,
    /// PLOC with a medium radius and reinsertion: about Embree's build time, faster traversal.
    #[default]
    Medium,
    /// Wide PLOC search and heavy reinsertion: slowest build, best traversal.
    Slow,
}

impl BvhPreset {
    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            BvhPreset::Fast => "fast",
            BvhPreset::Medium => "medium",
            BvhPreset::Slow => "slow",
        }
    }

    /// Parses a sidecar value.
    pub fn parse(s: &str) -> Option<BvhPreset> {
        <BvhPreset as ValueEnum>::from_str(s, false).ok()
    }
}

/// Voxel grid resolution: cells along the scene's longest axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VoxelRes {
    /// The cube root of the triangle count, clamped to 4..=64.
    #[default]
    Auto,
    /// This many cells.
    Cells(u32),
}

impl VoxelRes {
    /// Parses `auto` or a cell count in 1..=1024.
    pub fn parse(s: &str) -> Result<VoxelRes, String> {
        if s == "auto" {
            return Ok(VoxelRes::Auto);
        }
        match s.parse::<u32>() {
            Ok(n) if (1..=1024).contains(&n) => Ok(VoxelRes::Cells(n)),
            _ => Err(format!("'{s}' is neither 'auto' nor a cell count in 1..=1024")),
        }
    }

    /// As text.
    pub fn name(self) -> String {
        match self {
            VoxelRes::Auto => "auto".into(),
            VoxelRes::Cells(n) => n.to_string(),
        }
    }
}

/// Default shaft resolution: 4 patches per face edge, 3,840 shafts per voxel (the thesis used 5,
/// 9,375 shafts; 4 keeps binary and PNMT data 2.4× smaller at the same voxel resolution).
pub const DEFAULT_SHAFT_RES: u32 = 4;

/// Parses a `--shaft-variants` list: `binary`, `candidates`, `pnmt` separated by commas, or
/// `none`.
pub fn parse_variants(s: &str) -> Result<u32, String> {
    if s == "none" {
        return Ok(0);
    }
    let mut v = 0;
    for part in s.split(',').map(str::trim) {
        v |= match part {
            "binary" => Variants::BINARY,
            "candidates" => Variants::CANDIDATES,
            "pnmt" => Variants::PNMT,
            other => {
                return Err(format!(
                    "unknown shaft variant '{other}' (use binary, candidates, pnmt or none)"
                ));
            }
        };
    }
    Ok(v)
}

/// A variant set as text.
pub fn variants_name(v: u32) -> String {
    let names: Vec<&str> =
        [(Variants::BINARY, "binary"), (Variants::CANDIDATES, "candidates"), (Variants::PNMT, "pnmt")]
            .into_iter()
            .filter_map(|(bit, name)| (v & bit != 0).then_some(name))
            .collect();
    if names.is_empty() { "none".into() } else { names.join(",") }
}

/// Every setting that affects the output file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Settings {
    /// BVH preset.
    pub bvh_preset: BvhPreset,
    /// Voxel grid resolution.
    pub voxel_res: VoxelRes,
    /// Shaft resolution N.
    pub shaft_res: u32,
    /// Line-space variants; `None` lets the plan choose.
    pub shaft_variants: Option<u32>,
    /// BRDF table size.
    pub brdf_lut_res: u32,
    /// Shadow map size (2D maps; cube faces get half).
    pub shadow_res: u32,
    /// Light-visibility volume cells along the medium's longest axis.
    pub media_volume_res: u32,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            bvh_preset: BvhPreset::default(),
            voxel_res: VoxelRes::Auto,
            shaft_res: DEFAULT_SHAFT_RES,
            shaft_variants: None,
            brdf_lut_res: crate::bake::brdf_lut::DEFAULT_RESOLUTION,
            shadow_res: crate::bake::shadow::DEFAULT_RESOLUTION,
            media_volume_res: crate::bake::media::DEFAULT_RESOLUTION,
        }
    }
}

impl Settings {
    /// The settings as key/value pairs for the manifest and content hashes.
    pub fn pairs(&self) -> Vec<(String, String)> {
        vec![
            ("bvh-preset".into(), self.bvh_preset.name().into()),
            ("voxel-res".into(), self.voxel_res.name()),
            ("shaft-res".into(), self.shaft_res.to_string()),
            ("shaft-variants".into(), self.shaft_variants.map_or_else(|| "plan".into(), variants_name)),
            ("brdf-lut-res".into(), self.brdf_lut_res.to_string()),
            ("shadow-res".into(), self.shadow_res.to_string()),
            ("media-volume-res".into(), self.media_volume_res.to_string()),
        ]
    }
}
