//! Bake settings: what the command line and the sidecar's `[bake]` table decide.

use clap::ValueEnum;

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

/// Every setting that affects the output file.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Settings {
    /// BVH preset.
    pub bvh_preset: BvhPreset,
}

impl Settings {
    /// The settings as key/value pairs for the manifest and content hashes.
    pub fn pairs(&self) -> Vec<(String, String)> {
        vec![("bvh-preset".into(), self.bvh_preset.name().into())]
    }
}
