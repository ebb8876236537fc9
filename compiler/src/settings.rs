//! Bake settings: what the command line and the sidecar's `[bake]` table decide.

use clap::ValueEnum;
use kiln_format::linespace::Variants;

use crate::import::sidecar::BakeToml;

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

/// Whether the irradiance probe volume is baked (`--probes`, `[bake] probes`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum Probes {
    /// Baked whenever something lights the scene.
    #[default]
    Auto,
    /// Never baked.
    Off,
}

impl Probes {
    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Probes::Auto => "auto",
            Probes::Off => "off",
        }
    }

    /// Parses a sidecar value.
    pub fn parse(s: &str) -> Option<Probes> {
        <Probes as ValueEnum>::from_str(s, false).ok()
    }
}

/// Distance between probes in scene units (`--probe-spacing`): finite and positive; compared
/// bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeSpacing(pub f32);

impl Eq for ProbeSpacing {}

impl ProbeSpacing {
    /// Parses a positive, finite number.
    pub fn parse(s: &str) -> Result<ProbeSpacing, String> {
        match s.trim().parse::<f32>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(ProbeSpacing(v)),
            _ => Err(format!("'{s}' is not a positive distance in scene units")),
        }
    }
}

/// The least perceptual roughness the probe bake gives the surfaces its paths meet
/// (`--probe-regularize`): 0 to 1; compared bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeRegularize(pub f32);

impl Eq for ProbeRegularize {}

impl ProbeRegularize {
    /// Path regularisation of the probe bake by default: surfaces at least as rough as 0.5.
    /// Probes store irradiance, a cosine-weighted mean over the sphere, so a glossy surface's
    /// highlight seen by a probe path counts for its energy, not for where it sits; widening the
    /// lobe keeps the energy (GGX is normalised) and removes the fireflies of highlights that
    /// one path in thousands catches (pica_pica's walls, roughness 0.11, under its point light:
    /// ±20 % patches between neighbouring probes at 256 paths).
    pub const DEFAULT: ProbeRegularize = ProbeRegularize(0.5);

    /// Parses a finite number from 0 to 1.
    pub fn parse(s: &str) -> Result<ProbeRegularize, String> {
        match s.trim().parse::<f32>() {
            Ok(v) if (0.0..=1.0).contains(&v) => Ok(ProbeRegularize(v)),
            _ => Err(format!("'{s}' is not a roughness from 0 to 1")),
        }
    }
}

/// How PNMT records are stored (`--pnmt-records`, `[bake] pnmt_records`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum PnmtRecords {
    /// 12 bytes a record (8 where no material samples a texture): positions in 1/1023 of a
    /// cell, normals within 0.12°, material indices up to 4094 (scenes of more than 4,095
    /// materials fall back to full).
    #[default]
    Compact,
    /// 16 bytes a record: positions in 1/65535 of a cell, normals within 0.005°.
    Full,
}

impl PnmtRecords {
    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            PnmtRecords::Compact => "compact",
            PnmtRecords::Full => "full",
        }
    }

    /// Parses a sidecar value.
    pub fn parse(s: &str) -> Option<PnmtRecords> {
        <PnmtRecords as ValueEnum>::from_str(s, false).ok()
    }
}

/// How textures are stored (`--texture-format`, `[bake] texture_format`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum TextureFormat {
    /// Block-compressed by role: BC7 for colour (sRGB) and for data textures whose three channels
    /// are all read, BC5 for normal maps (x, y; z is reconstructed) and metallic-roughness (G, B),
    /// BC4 for occlusion (R). A quarter (BC7, BC5) or an eighth (BC4) of RGBA8's bytes; the
    /// player needs the device feature `textureCompressionBC`.
    #[default]
    Bc,
    /// Uncompressed RGBA8 (exact; every device samples it).
    Rgba8,
}

impl TextureFormat {
    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TextureFormat::Bc => "bc",
            TextureFormat::Rgba8 => "rgba8",
        }
    }

    /// Parses a sidecar value.
    pub fn parse(s: &str) -> Option<TextureFormat> {
        <TextureFormat as ValueEnum>::from_str(s, false).ok()
    }
}

/// A numeric setting: its name, default and valid range. The command line (through
/// [`Ranged::parser`]) and the sidecar's `[bake]` table (through [`Ranged::check`]) both check
/// values against it, and [`Settings::default`] takes its default from it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ranged {
    /// Key in the sidecar's `[bake]` table; the command-line option and the manifest key are the
    /// same with `-` for `_`.
    pub key: &'static str,
    /// Default.
    pub default: u32,
    /// Smallest valid value.
    pub min: u32,
    /// Largest valid value.
    pub max: u32,
}

impl Ranged {
    /// `value`, or an error naming the key and the valid range (for the sidecar).
    pub fn check(&self, value: u32) -> Result<u32, String> {
        if (self.min..=self.max).contains(&value) {
            Ok(value)
        } else {
            Err(format!("{} is {value}; use {}..={}", self.key, self.min, self.max))
        }
    }

    /// The command-line parser: clap's range check, whose error names the option and the range.
    pub fn parser(&self) -> clap::builder::RangedI64ValueParser<u32> {
        clap::value_parser!(u32).range(self.min as i64..=self.max as i64)
    }

    /// Help text: `what`, the valid range and the default.
    pub fn help(&self, what: &str) -> String {
        format!("{what}, {}..={} [default: {}]", self.min, self.max, self.default)
    }
}

/// Shaft resolution N (patches per voxel face edge): 4 by default, 3,840 shafts per voxel (the
/// thesis used 5, 9,375 shafts; 4 keeps binary and PNMT data 2.4× smaller at the same voxel
/// resolution).
pub const SHAFT_RES: Ranged =
    Ranged { key: "shaft_res", default: 4, min: 1, max: kiln_format::linespace::index::MAX_SHAFT_RES };

/// Size budget of the voxel grid and line space sections, MiB (`--line-space-budget`): the plan
/// lowers the voxel resolution, then N (and drops variants it chose itself) until the estimate
/// fits; see [`crate::analyze::budget`]. The default scales with the scene's geometry
/// ([`crate::analyze::budget::default_budget_mib`]; `default` here is its ceiling) and guards
/// only the plan's own choices.
pub const LINE_SPACE_BUDGET: Ranged = Ranged {
    key: "line_space_budget",
    default: crate::analyze::budget::DEFAULT_BUDGET_MAX_MIB,
    min: 1,
    max: 1 << 20,
};

/// BRDF table size: the integrals are smooth, so 128 × 128 keeps bilinear interpolation error
/// far below the 16-bit quantisation step's effect on shading, in 64 KiB.
pub const BRDF_LUT_RES: Ranged = Ranged { key: "brdf_lut_res", default: 128, min: 8, max: 1024 };

/// Resolution of 2D shadow maps; cube faces get half of it (each covers 90°).
pub const SHADOW_RES: Ranged = Ranged { key: "shadow_res", default: 1024, min: 16, max: 8192 };

/// Light-visibility volume cells along the medium box's longest axis.
pub const MEDIA_VOLUME_RES: Ranged = Ranged { key: "media_volume_res", default: 64, min: 2, max: 512 };

/// Rays traced per probe of the irradiance volume (each a path of every bounce; a quarter as
/// many next-event samples of the emissive triangles join them). The default is for scenes whose
/// every material is pure Lambertian; [`PROBE_RAYS_GLOSSY`] where one has a specular lobe.
pub const PROBE_RAYS: Ranged = Ranged { key: "probe_rays", default: 256, min: 16, max: 65536 };

/// [`PROBE_RAYS`]' default for a scene with a glossy (not pure Lambertian) material. Light
/// reflected off glossy surfaces reaches a probe concentrated in few directions, even with the
/// paths regularised: pica_pica's one-frame FLIP (`probes-rt`, H200 reference) was 0.0453 at 256
/// paths, 0.0452 at 512 and 0.0426 at 1,024 (docs/benchmarks/probe-rays/). Lambertian scenes
/// such as the demo keep 256: the test suite compiles it dozens of times.
pub const PROBE_RAYS_GLOSSY: u32 = 1024;

/// Size budget of the probe volume, MiB, when its spacing is chosen from the scene's size.
pub const PROBE_BUDGET: Ranged = Ranged { key: "probe_budget", default: 2, min: 1, max: 4096 };

/// Width of the environment's radiance map in texels (its height is half); a narrower image
/// keeps its own width.
pub const ENVIRONMENT_RES: Ranged = Ranged { key: "environment_res", default: 1024, min: 16, max: 8192 };

/// Voxel grid cells along the scene's longest axis when given as a number (the default is
/// [`VoxelRes::Auto`], so [`Ranged::default`] is unused here).
pub const VOXEL_RES: Ranged = Ranged { key: "voxel_res", default: 0, min: 1, max: 1024 };

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
    /// Parses `auto` or a cell count in [`VOXEL_RES`]'s range.
    pub fn parse(s: &str) -> Result<VoxelRes, String> {
        if s == "auto" {
            return Ok(VoxelRes::Auto);
        }
        match s.parse::<u32>() {
            Ok(n) if (VOXEL_RES.min..=VOXEL_RES.max).contains(&n) => Ok(VoxelRes::Cells(n)),
            _ => Err(format!(
                "'{s}' is neither 'auto' nor a cell count in {}..={}",
                VOXEL_RES.min, VOXEL_RES.max
            )),
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

/// Parses a `--shaft-variants` list: `binary`, `candidates`, `pnmt` separated by commas, or
/// `none`.
pub fn parse_variants(s: &str) -> Result<u32, String> {
    if s == "none" {
        return Ok(0);
    }
    let mut v = 0;
    for part in s.split(',').map(str::trim) {
        v |=
            Variants::NAMES.iter().find(|(_, name)| *name == part).map(|(bit, _)| *bit).ok_or_else(|| {
                format!("unknown shaft variant '{part}' (use binary, candidates, pnmt, preillum or none)")
            })?;
    }
    Ok(v)
}

/// A variant set as text.
pub fn variants_name(v: u32) -> String {
    Variants::list(v)
}

/// Largest crease angle of `--normals smooth:ANGLE`, degrees.
pub const MAX_CREASE_DEGREES: f32 = 180.0;

/// How vertex normals are made where the asset gives none (`--normals`, `[bake] normals`).
/// Normals the asset gives are always kept.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Normals {
    /// What the format says: glTF flat (glTF 2.0, "Vertex attributes": "client implementations
    /// MUST calculate flat normals"), OBJ by its smoothing groups (`s N` smooth within group N,
    /// `s off`, `s 0` or none flat).
    #[default]
    Asset,
    /// Every triangle its own face normal.
    Flat,
    /// Angle-weighted vertex normals over all triangles at a vertex, except across edges whose
    /// face normals differ by more than `crease_degrees` (`None`: no crease, smooth everywhere).
    Smooth {
        /// Crease angle in degrees, in `0..=180`.
        crease_degrees: Option<f32>,
    },
}

// The crease angle is checked finite when parsed, so equality is reflexive.
impl Eq for Normals {}

impl Normals {
    /// Parses `asset`, `flat`, `smooth` or `smooth:ANGLE` (degrees, 0..=180).
    pub fn parse(s: &str) -> Result<Normals, String> {
        let usage = "use flat, smooth or smooth:ANGLE (crease angle in degrees, 0..=180)";
        match s {
            "asset" => Ok(Normals::Asset),
            "flat" => Ok(Normals::Flat),
            "smooth" => Ok(Normals::Smooth { crease_degrees: None }),
            _ => {
                let Some(angle) = s.strip_prefix("smooth:") else {
                    return Err(format!("'{s}' is not a normals mode; {usage}"));
                };
                match angle.trim().parse::<f32>() {
                    Ok(a) if a.is_finite() && (0.0..=MAX_CREASE_DEGREES).contains(&a) => {
                        Ok(Normals::Smooth { crease_degrees: Some(a) })
                    }
                    _ => {
                        Err(format!("crease angle '{angle}' is not a number of degrees in 0..=180; {usage}"))
                    }
                }
            }
        }
    }

    /// As text (parses back to the same value).
    pub fn name(self) -> String {
        match self {
            Normals::Asset => "asset".into(),
            Normals::Flat => "flat".into(),
            Normals::Smooth { crease_degrees: None } => "smooth".into(),
            Normals::Smooth { crease_degrees: Some(a) } => format!("smooth:{a}"),
        }
    }
}

/// Which sections the output file stores compressed (FORMAT.md "Codecs").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Codec {
    /// zstd for every section it shrinks by at least [`kiln_format::DEFAULT_MIN_SAVING`]; the
    /// rest stays as is (zero-copy).
    #[default]
    Auto,
    /// Every section stored as is.
    None,
    /// Every section zstd-compressed (smallest file, for distribution; the player decodes
    /// each section once while loading).
    Zstd,
}

impl Codec {
    /// Parses `auto`, `none` or `zstd`.
    pub fn parse(s: &str) -> Result<Codec, String> {
        match s {
            "auto" => Ok(Codec::Auto),
            "none" => Ok(Codec::None),
            "zstd" => Ok(Codec::Zstd),
            _ => Err(format!("'{s}' is not a codec; use auto, none or zstd")),
        }
    }

    /// As text (parses back to the same value).
    pub fn name(self) -> &'static str {
        match self {
            Codec::Auto => "auto",
            Codec::None => "none",
            Codec::Zstd => "zstd",
        }
    }

    /// What the writer does.
    pub fn compression(self) -> kiln_format::Compression {
        match self {
            Codec::Auto => kiln_format::Compression::Default,
            Codec::None => kiln_format::Compression::None,
            Codec::Zstd => kiln_format::Compression::All,
        }
    }
}

/// Every setting that affects the output file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Settings {
    /// BVH preset.
    pub bvh_preset: BvhPreset,
    /// Voxel grid resolution.
    pub voxel_res: VoxelRes,
    /// Shaft resolution N; `None`: [`SHAFT_RES`]'s default, which a budget may lower.
    pub shaft_res: Option<u32>,
    /// Line-space variants; `None` lets the plan choose.
    pub shaft_variants: Option<u32>,
    /// Budget of the grid and line space, MiB; `None`: [`LINE_SPACE_BUDGET`]'s default, applied
    /// only when the plan chooses the variants.
    pub line_space_budget: Option<u32>,
    /// BRDF table size.
    pub brdf_lut_res: u32,
    /// Shadow map size (2D maps; cube faces get half).
    pub shadow_res: u32,
    /// Light-visibility volume cells along the medium's longest axis.
    pub media_volume_res: u32,
    /// Whether the probe volume is baked.
    pub probes: Probes,
    /// Probe spacing; `None`: from the scene's size within [`PROBE_BUDGET`].
    pub probe_spacing: Option<ProbeSpacing>,
    /// Rays per probe; `None`: [`PROBE_RAYS`]' default, [`PROBE_RAYS_GLOSSY`] for a scene with a
    /// glossy material.
    pub probe_rays: Option<u32>,
    /// Probe volume budget, MiB (when the spacing is chosen).
    pub probe_budget: u32,
    /// Least roughness of the surfaces the probe paths meet.
    pub probe_regularize: ProbeRegularize,
    /// Widest environment radiance map, texels.
    pub environment_res: u32,
    /// Normals where the asset gives none (applied at import).
    pub normals: Normals,
    /// Which sections are stored compressed. Changes the stored bytes only, never a section's
    /// decoded bytes or content hash (so cached stages are reused across codecs).
    pub codec: Codec,
    /// How textures are stored.
    pub texture_format: TextureFormat,
    /// How PNMT records are stored.
    pub pnmt_records: PnmtRecords,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            bvh_preset: BvhPreset::default(),
            voxel_res: VoxelRes::Auto,
            shaft_res: None,
            shaft_variants: None,
            line_space_budget: None,
            brdf_lut_res: BRDF_LUT_RES.default,
            shadow_res: SHADOW_RES.default,
            media_volume_res: MEDIA_VOLUME_RES.default,
            probes: Probes::Auto,
            probe_spacing: None,
            probe_rays: None,
            probe_budget: PROBE_BUDGET.default,
            probe_regularize: ProbeRegularize::DEFAULT,
            environment_res: ENVIRONMENT_RES.default,
            normals: Normals::Asset,
            codec: Codec::Auto,
            texture_format: TextureFormat::default(),
            pnmt_records: PnmtRecords::default(),
        }
    }
}

impl Settings {
    /// Applies the sidecar's `[bake]` table; the error names the key and what it accepts.
    pub fn apply_bake_table(&mut self, b: &BakeToml) -> Result<(), String> {
        if let Some(p) = &b.bvh_preset {
            self.bvh_preset = BvhPreset::parse(p)
                .ok_or_else(|| format!("bvh_preset is '{p}'; use fast, medium or slow"))?;
        }
        if let Some(v) = &b.voxel_res {
            let text = match v {
                toml::Value::String(s) => s.clone(),
                toml::Value::Integer(i) => i.to_string(),
                other => other.to_string(),
            };
            self.voxel_res = VoxelRes::parse(&text).map_err(|e| format!("voxel_res: {e}"))?;
        }
        for (table, value, setting) in [
            (SHAFT_RES, b.shaft_res, &mut self.shaft_res),
            (LINE_SPACE_BUDGET, b.line_space_budget, &mut self.line_space_budget),
            (PROBE_RAYS, b.probe_rays, &mut self.probe_rays),
        ] {
            if let Some(n) = value {
                *setting = Some(table.check(n)?);
            }
        }
        for (table, value, setting) in [
            (BRDF_LUT_RES, b.brdf_lut_res, &mut self.brdf_lut_res),
            (SHADOW_RES, b.shadow_res, &mut self.shadow_res),
            (MEDIA_VOLUME_RES, b.media_volume_res, &mut self.media_volume_res),
            (PROBE_BUDGET, b.probe_budget, &mut self.probe_budget),
            (ENVIRONMENT_RES, b.environment_res, &mut self.environment_res),
        ] {
            if let Some(n) = value {
                *setting = table.check(n)?;
            }
        }
        if let Some(v) = &b.shaft_variants {
            self.shaft_variants = Some(parse_variants(v).map_err(|e| format!("shaft_variants: {e}"))?);
        }
        if let Some(f) = &b.texture_format {
            self.texture_format =
                TextureFormat::parse(f).ok_or_else(|| format!("texture_format is '{f}'; use bc or rgba8"))?;
        }
        if let Some(p) = &b.pnmt_records {
            self.pnmt_records =
                PnmtRecords::parse(p).ok_or_else(|| format!("pnmt_records is '{p}'; use compact or full"))?;
        }
        if let Some(p) = &b.probes {
            self.probes = Probes::parse(p).ok_or_else(|| format!("probes is '{p}'; use auto or off"))?;
        }
        if let Some(v) = b.probe_spacing {
            self.probe_spacing =
                Some(ProbeSpacing::parse(&v.to_string()).map_err(|e| format!("probe_spacing: {e}"))?);
        }
        if let Some(v) = b.probe_regularize {
            self.probe_regularize =
                ProbeRegularize::parse(&v.to_string()).map_err(|e| format!("probe_regularize: {e}"))?;
        }
        if let Some(n) = &b.normals {
            self.normals = Normals::parse(n).map_err(|e| format!("normals: {e}"))?;
        }
        if let Some(c) = &b.codec {
            self.codec = Codec::parse(c).map_err(|e| format!("codec: {e}"))?;
        }
        Ok(())
    }

    /// The settings as key/value pairs for the manifest and content hashes.
    pub fn pairs(&self) -> Vec<(String, String)> {
        vec![
            ("bvh-preset".into(), self.bvh_preset.name().into()),
            ("voxel-res".into(), self.voxel_res.name()),
            ("shaft-res".into(), self.shaft_res.map_or_else(|| "plan".into(), |n| n.to_string())),
            ("shaft-variants".into(), self.shaft_variants.map_or_else(|| "plan".into(), variants_name)),
            (
                "line-space-budget".into(),
                self.line_space_budget
                    .map_or_else(|| "default, scaled to the geometry".into(), |n| n.to_string()),
            ),
            ("brdf-lut-res".into(), self.brdf_lut_res.to_string()),
            ("shadow-res".into(), self.shadow_res.to_string()),
            ("media-volume-res".into(), self.media_volume_res.to_string()),
            ("probes".into(), self.probes.name().into()),
            ("probe-spacing".into(), self.probe_spacing.map_or_else(|| "plan".into(), |s| s.0.to_string())),
            (
                "probe-rays".into(),
                self.probe_rays.map_or_else(
                    || format!("default: {}, {PROBE_RAYS_GLOSSY} with glossy materials", PROBE_RAYS.default),
                    |n| n.to_string(),
                ),
            ),
            ("probe-budget".into(), self.probe_budget.to_string()),
            ("probe-regularize".into(), self.probe_regularize.0.to_string()),
            ("environment-res".into(), self.environment_res.to_string()),
            ("normals".into(), self.normals.name()),
            ("codec".into(), self.codec.name().into()),
            ("texture-format".into(), self.texture_format.name().into()),
            ("pnmt-records".into(), self.pnmt_records.name().into()),
        ]
    }
}
