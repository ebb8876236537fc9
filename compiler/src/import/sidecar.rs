//! The TOML sidecar: what an asset lacks (camera, lights, sky, media, material fixes) and bake
//! settings. Unknown keys are rejected by name. The schema is documented in `docs/sidecar.md`.

use std::collections::BTreeMap;
use std::path::Path;

use glam::{DVec3, Vec3};
use kiln_format::manifest::{Bounds, Camera, Light, LightKind, Medium, Sky};
use kiln_format::sections::MaterialFlags;
use serde::Deserialize;

use crate::exit::{CliError, CliResult};
use crate::import::environment::{self, EnvironmentSpec, Placement};
use crate::import::geometry::stored;
use crate::ir::Scene;

/// A parsed sidecar.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sidecar {
    /// The default camera (replaces the asset's first camera as the default).
    pub camera: Option<CameraToml>,
    /// Lights added to the asset's own.
    #[serde(default, rename = "light")]
    pub lights: Vec<LightToml>,
    /// Constant sky.
    pub sky: Option<SkyToml>,
    /// Homogeneous media.
    #[serde(default, rename = "medium")]
    pub media: Vec<MediumToml>,
    /// Material overrides by material name.
    #[serde(default, rename = "material")]
    pub materials: BTreeMap<String, MaterialToml>,
    /// Bake settings (the command line overrides them).
    #[serde(default)]
    pub bake: BakeToml,
    /// The directory relative paths in it start from.
    #[serde(skip)]
    pub dir: std::path::PathBuf,
}

/// `[camera]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraToml {
    /// Eye position (world space; read in double precision, as every position of the sidecar,
    /// so that a scene far from the origin keeps its precision: see `Scene::origin`).
    pub position: [f64; 3],
    /// Point looked at.
    pub target: [f64; 3],
    /// Up vector.
    #[serde(default = "up")]
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    #[serde(default = "vfov")]
    pub vfov_degrees: f32,
    /// Near plane (default: 1/1000 of the scene's diagonal).
    pub znear: Option<f32>,
    /// Far plane (default: infinite).
    pub zfar: Option<f32>,
}

/// The header (`[camera]`, `[[light]]`, `[material."x"]`) of the table whose body holds byte
/// `at`; `None` on a header line itself or before the first header.
fn enclosing_table(text: &str, at: usize) -> Option<&str> {
    let line_start = text.get(..at)?.rfind('\n').map_or(0, |i| i + 1);
    if text[line_start..].trim_start().starts_with('[') {
        return None;
    }
    let header = text[..line_start].lines().rev().map(str::trim).find(|l| l.starts_with('['))?;
    // A header may carry a comment; table names here hold no `#`.
    Some(header.split('#').next().unwrap_or(header).trim_end())
}

fn up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
fn vfov() -> f32 {
    45.0
}
fn white() -> [f32; 3] {
    [1.0; 3]
}
fn yes() -> bool {
    true
}

/// Light kinds of the sidecar.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKindToml {
    /// Point light.
    Point,
    /// Spot light.
    Spot,
    /// Directional light.
    Directional,
    /// One-sided rectangular area light.
    Rect,
}

/// `[[light]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightToml {
    /// Kind.
    pub kind: LightKindToml,
    /// Name (default `light<N>`).
    pub name: Option<String>,
    /// Position (point, spot, rect centre).
    pub position: Option<[f64; 3]>,
    /// Linear RGB colour.
    #[serde(default = "white")]
    pub color: [f32; 3],
    /// Point, spot: W/sr; directional: W/m²; rect: W/(sr·m²).
    pub intensity: f32,
    /// Directional and spot: where the light travels; rect: the side it emits to.
    pub direction: Option<[f32; 3]>,
    /// Rect: `[width, height]`.
    pub size: Option<[f32; 2]>,
    /// Rect: the direction of the width.
    pub right: Option<[f32; 3]>,
    /// Spot: full intensity inside this half-angle (default 0.8 × outer).
    pub inner_cone_degrees: Option<f32>,
    /// Spot: zero intensity outside this half-angle (default 45).
    pub outer_cone_degrees: Option<f32>,
    /// Cut-off distance (default unlimited).
    pub range: Option<f32>,
    /// Whether it casts shadows (default true).
    #[serde(default = "yes")]
    pub casts_shadows: bool,
}

/// `[sky]`: a constant radiance, or an environment (an HDR image or a sky model).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkyToml {
    /// Constant radiance W/(sr·m²), linear RGB.
    pub radiance: Option<[f32; 3]>,
    /// Equirectangular Radiance .hdr or OpenEXR image, relative to the sidecar.
    pub image: Option<std::path::PathBuf>,
    /// `"preetham"` (daylight and its sun) or `"studio"` (the built-in neutral environment).
    pub model: Option<String>,
    /// Multiplies the environment's radiance (and the Preetham sun's).
    pub intensity: Option<f32>,
    /// Rotation of the environment about +y, degrees.
    pub rotation_degrees: Option<f32>,
    /// Preetham: unit direction towards the sun (y up).
    pub sun_direction: Option<[f32; 3]>,
    /// Preetham: turbidity, 1.7 to 10.
    pub turbidity: Option<f32>,
    /// Preetham: whether the sun is added as a directional light; an image: whether a sun found
    /// in it is taken out as a directional light (default true).
    pub sun: Option<bool>,
}

impl SkyToml {
    /// The environment this table asks for (`None`: a constant sky at most); the error names
    /// the key at fault.
    pub fn environment(&self, dir: &Path) -> Result<Option<(EnvironmentSpec, Placement)>, String> {
        use crate::import::preetham;
        let spec = match (&self.image, self.model.as_deref()) {
            (Some(_), Some(_)) => return Err("give [sky] image or model, not both".into()),
            (Some(image), None) => {
                EnvironmentSpec::Image { path: dir.join(image), extract_sun: self.sun.unwrap_or(true) }
            }
            (None, Some("preetham")) => EnvironmentSpec::Preetham {
                sun_direction: self.sun_direction.unwrap_or(preetham::DEFAULT_SUN),
                turbidity: self.turbidity.unwrap_or(preetham::DEFAULT_TURBIDITY),
                sun: self.sun.unwrap_or(true),
            },
            (None, Some("studio")) => EnvironmentSpec::Studio,
            (None, Some(other)) => {
                return Err(format!("[sky] model = \"{other}\" is not known: \"preetham\" or \"studio\""));
            }
            (None, None) => {
                if self.intensity.is_some() || self.rotation_degrees.is_some() {
                    return Err("[sky] intensity and rotation_degrees need an image or a model".into());
                }
                if self.sun_direction.is_some() || self.turbidity.is_some() || self.sun.is_some() {
                    return Err(
                        "[sky] sun_direction, turbidity and sun belong to model = \"preetham\"".into()
                    );
                }
                return Ok(None);
            }
        };
        if !matches!(spec, EnvironmentSpec::Preetham { .. })
            && (self.sun_direction.is_some() || self.turbidity.is_some())
        {
            return Err("[sky] sun_direction and turbidity belong to model = \"preetham\"".into());
        }
        if matches!(spec, EnvironmentSpec::Studio) && self.sun.is_some() {
            return Err(
                "[sky] sun belongs to model = \"preetham\" (add its sun) or an image (take its sun out)"
                    .into(),
            );
        }
        if self.radiance.is_some() {
            return Err("[sky] radiance is a constant sky: leave it out with an image or a model".into());
        }
        let d = Placement::default();
        Ok(Some((
            spec,
            Placement {
                intensity: self.intensity.unwrap_or(d.intensity),
                rotation_degrees: self.rotation_degrees.unwrap_or(d.rotation_degrees),
            },
        )))
    }
}

/// `[[medium]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MediumToml {
    /// Minimum corner of the box it fills (default: the scene bounds).
    pub min: Option<[f64; 3]>,
    /// Maximum corner.
    pub max: Option<[f64; 3]>,
    /// Absorption per scene unit, RGB.
    #[serde(default)]
    pub sigma_a: [f32; 3],
    /// Scattering per scene unit, RGB.
    pub sigma_s: [f32; 3],
    /// Henyey–Greenstein g in (-1, 1).
    #[serde(default)]
    pub g: f32,
}

/// `[material."NAME"]`: fields replace the asset's values.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialToml {
    /// Linear RGB or RGBA base colour.
    pub base_color: Option<Vec<f32>>,
    /// Emitted radiance W/(sr·m²), linear RGB.
    pub emission: Option<[f32; 3]>,
    /// Metalness.
    pub metallic: Option<f32>,
    /// Perceptual roughness.
    pub roughness: Option<f32>,
    /// Clear coat strength (glTF `KHR_materials_clearcoat`).
    pub clearcoat: Option<f32>,
    /// The clear coat's perceptual roughness.
    pub clearcoat_roughness: Option<f32>,
    /// Thin-walled transmission (glTF `KHR_materials_transmission`).
    pub transmission: Option<f32>,
    /// Pure Lambertian (no specular lobe).
    pub diffuse_only: Option<bool>,
    /// Shade both faces.
    pub double_sided: Option<bool>,
}

/// `[bake]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BakeToml {
    /// `fast`, `medium` or `slow`.
    pub bvh_preset: Option<String>,
    /// `bc` or `rgba8`.
    pub texture_format: Option<String>,
    /// `"auto"` or a cell count.
    pub voxel_res: Option<toml::Value>,
    /// Shaft resolution 1..=8.
    pub shaft_res: Option<u32>,
    /// Comma-separated variants or `"none"`.
    pub shaft_variants: Option<String>,
    /// Budget of the grid and line space, MiB.
    pub line_space_budget: Option<u32>,
    /// `compact` or `full`.
    pub pnmt_records: Option<String>,
    /// BRDF table size.
    pub brdf_lut_res: Option<u32>,
    /// Shadow map size.
    pub shadow_res: Option<u32>,
    /// Light-visibility volume resolution.
    pub media_volume_res: Option<u32>,
    /// `"auto"` or `"off"`: whether the irradiance probe volume is baked.
    pub probes: Option<String>,
    /// Distance between probes, scene units.
    pub probe_spacing: Option<f64>,
    /// Rays per probe.
    pub probe_rays: Option<u32>,
    /// Budget of the probe volume, MiB.
    pub probe_budget: Option<u32>,
    /// Least roughness of the surfaces the probe paths meet, 0 to 1.
    pub probe_regularize: Option<f64>,
    /// Widest environment radiance map, texels.
    pub environment_res: Option<u32>,
    /// Normals where the asset gives none: `"flat"`, `"smooth"` or `"smooth:ANGLE"`.
    pub normals: Option<String>,
    /// Which sections are compressed: `"auto"`, `"none"` or `"zstd"`.
    pub codec: Option<String>,
}

impl Sidecar {
    /// Reads and parses a sidecar file.
    pub fn load(path: &Path, inputs: &mut Vec<std::path::PathBuf>) -> CliResult<Sidecar> {
        let bytes = super::read_input(path, inputs)?;
        let text = String::from_utf8(bytes)
            .map_err(|_| CliError::input(format!("{}: not UTF-8 text", path.display())))?;
        let mut sidecar =
            Self::parse(&text).map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
        sidecar.dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok(sidecar)
    }

    /// Parses sidecar text. An error inside a table names the table (`in [[light]]: …`): a TOML
    /// error shows only the offending line, and `colour` reads the same in every table.
    pub fn parse(text: &str) -> Result<Sidecar, String> {
        toml::from_str(text).map_err(|e: toml::de::Error| {
            let msg = e.to_string().trim_end().replace('\n', " ");
            match e.span().and_then(|span| enclosing_table(text, span.start)) {
                Some(table) => format!("in {table}: {msg}"),
                None => msg,
            }
        })
    }

    /// Applies the sidecar to an imported scene; `source` names the file in messages.
    pub fn apply(&self, scene: &mut Scene, source: &str) -> CliResult<()> {
        let err = |msg: String| CliError::input(format!("{source}: {msg}"));
        let bad = |msg: String| Err(err(msg));
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        // Positions are stored relative to the scene's origin (`Scene::origin`).
        let origin = DVec3::from(scene.origin);
        let rel = |p: [f64; 3]| stored(DVec3::from(p), origin);
        if let Some(c) = &self.camera {
            let vals = [&c.up[..], &[c.vfov_degrees]].concat();
            let (position, target) = (rel(c.position), rel(c.target));
            if !finite(&vals) || !finite(&[position, target].concat()) {
                return bad("[camera] has a non-finite value".into());
            }
            let fwd = Vec3::from(target) - Vec3::from(position);
            if fwd.length_squared() == 0.0 || fwd.cross(Vec3::from(c.up)).length_squared() == 0.0 {
                return bad("[camera] target equals position, or up is parallel to the view direction".into());
            }
            if !(c.vfov_degrees > 0.0 && c.vfov_degrees < 180.0) {
                return bad(format!("[camera] vfov_degrees is {}, must be in (0, 180)", c.vfov_degrees));
            }
            // The asset's cameras move up one place.
            for o in &mut scene.orthographic {
                o.camera += 1;
            }
            scene.cameras.insert(
                0,
                Camera {
                    name: "sidecar".into(),
                    position,
                    target,
                    up: c.up,
                    vfov_degrees: c.vfov_degrees,
                    znear: c.znear.unwrap_or(0.0),
                    zfar: c.zfar.unwrap_or(0.0),
                },
            );
        }
        for (i, l) in self.lights.iter().enumerate() {
            scene.lights.push(
                convert_light(l, i, origin)
                    .map_err(|e| err(format!("light {} ({:?}): {e}", i + 1, l.kind)))?,
            );
        }
        if let Some(s) = &self.sky {
            if let Some(radiance) = s.radiance {
                if !finite(&radiance) || radiance.iter().any(|&v| v < 0.0) {
                    return bad("[sky] radiance must be finite and non-negative".into());
                }
                scene.sky = Sky { radiance };
            }
            match s.environment(&self.dir).map_err(err)? {
                Some((spec, placement)) => environment::apply(scene, &spec, placement, source)?,
                // A constant sky (an empty `[sky]` is a black one) replaces the asset's environment.
                None => environment::replace_asset_environment(scene, source, "[sky], a constant sky"),
            }
        }
        for (i, m) in self.media.iter().enumerate() {
            let vals = [&m.sigma_a[..], &m.sigma_s, &[m.g]].concat();
            if !finite(&vals) || vals[..6].iter().any(|&v| v < 0.0) || !(m.g > -1.0 && m.g < 1.0) {
                return bad(format!(
                    "medium {}: coefficients must be finite and non-negative, g in (-1, 1)",
                    i + 1
                ));
            }
            let (min, max) = match (m.min, m.max) {
                (Some(a), Some(b)) => (rel(a), rel(b)),
                (None, None) => ([f32::NAN; 3], [f32::NAN; 3]), // filled with the scene bounds later
                _ => return bad(format!("medium {}: give both min and max, or neither", i + 1)),
            };
            scene.media.push(Medium {
                bounds: Bounds { min, max },
                sigma_a: m.sigma_a,
                sigma_s: m.sigma_s,
                g: m.g,
            });
        }
        for (name, o) in &self.materials {
            let mut found = false;
            for m in scene.materials.iter_mut().filter(|m| &m.name == name) {
                found = true;
                apply_material(o, &mut m.gpu).map_err(|e| err(format!("material \"{name}\": {e}")))?;
            }
            if !found {
                let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
                return bad(format!(
                    "material \"{name}\" is not in the scene (materials: {})",
                    names.join(", ")
                ));
            }
        }
        Ok(())
    }
}

fn apply_material(o: &MaterialToml, gpu: &mut kiln_format::sections::GpuMaterial) -> Result<(), String> {
    if let Some(c) = &o.base_color {
        match c.as_slice() {
            [r, g, b] => gpu.base_color = [*r, *g, *b, gpu.base_color[3]],
            [r, g, b, a] => gpu.base_color = [*r, *g, *b, *a],
            _ => return Err("base_color needs 3 or 4 numbers".into()),
        }
    }
    if let Some(e) = o.emission {
        gpu.emission = e;
    }
    if let Some(v) = o.metallic {
        gpu.metallic = v;
    }
    if let Some(v) = o.roughness {
        gpu.roughness = v;
    }
    if let Some(v) = o.clearcoat {
        gpu.clearcoat = v;
    }
    if let Some(v) = o.clearcoat_roughness {
        gpu.clearcoat_roughness = v;
    }
    if let Some(v) = o.transmission {
        gpu.transmission = v;
    }
    for (flag, value) in
        [(MaterialFlags::DIFFUSE_ONLY, o.diffuse_only), (MaterialFlags::DOUBLE_SIDED, o.double_sided)]
    {
        match value {
            Some(true) => gpu.flags |= flag,
            Some(false) => gpu.flags &= !flag,
            None => {}
        }
    }
    // Each field within what a material can be: a base colour above 1 reflects more light than
    // arrives (the glTF importer clamps it; a sidecar is written by hand, so it is refused).
    let fields: [(&str, &[f32], f32); 7] = [
        ("base_color", &gpu.base_color, 1.0),
        ("emission", &gpu.emission, f32::INFINITY),
        ("metallic", &[gpu.metallic], 1.0),
        ("roughness", &[gpu.roughness], 1.0),
        ("clearcoat", &[gpu.clearcoat], 1.0),
        ("clearcoat_roughness", &[gpu.clearcoat_roughness], 1.0),
        ("transmission", &[gpu.transmission], 1.0),
    ];
    for (field, values, most) in fields {
        if let Some(v) = values.iter().find(|v| !(v.is_finite() && (0.0..=most).contains(*v))) {
            let range =
                if most.is_finite() { format!("in [0, {most}]") } else { "finite and non-negative".into() };
            return Err(format!("{field} holds {v}; it must be {range}"));
        }
    }
    Ok(())
}

fn convert_light(l: &LightToml, i: usize, origin: DVec3) -> Result<Light, String> {
    let need = |v: Option<[f32; 3]>, what: &str| v.ok_or_else(|| format!("`{what}` is required"));
    let position = l.position.map(|p| stored(DVec3::from(p), origin));
    let unit = |v: [f32; 3], what: &str| {
        Vec3::from(v)
            .try_normalize()
            .map(|v| v.to_array())
            .ok_or_else(|| format!("`{what}` must be a non-zero vector"))
    };
    let mut light = Light {
        name: l.name.clone().unwrap_or_else(|| format!("light{}", i + 1)),
        kind: LightKind::Point,
        position: [0.0; 3],
        direction: [0.0, -1.0, 0.0],
        right: [0.0; 3],
        color: l.color,
        intensity: l.intensity,
        range: l.range.unwrap_or(0.0),
        casts_shadows: l.casts_shadows,
    };
    match l.kind {
        LightKindToml::Point => light.position = need(position, "position")?,
        LightKindToml::Directional => {
            light.kind = LightKind::Directional;
            light.direction = unit(need(l.direction, "direction")?, "direction")?;
        }
        LightKindToml::Spot => {
            light.position = need(position, "position")?;
            light.direction = unit(need(l.direction, "direction")?, "direction")?;
            let outer = l.outer_cone_degrees.unwrap_or(45.0);
            let inner = l.inner_cone_degrees.unwrap_or(0.8 * outer);
            if !(inner >= 0.0 && inner <= outer && outer > 0.0 && outer <= 90.0) {
                return Err(format!(
                    "cone angles must satisfy 0 <= inner ({inner}) <= outer ({outer}) <= 90 degrees, outer > 0"
                ));
            }
            light.kind = LightKind::Spot { inner_cone: inner.to_radians(), outer_cone: outer.to_radians() };
        }
        LightKindToml::Rect => {
            light.position = need(position, "position")?;
            let dir = Vec3::from(unit(need(l.direction, "direction")?, "direction")?);
            let right = Vec3::from(need(l.right, "right")?);
            // Keep only the part of `right` orthogonal to the direction.
            let right = (right - dir * right.dot(dir))
                .try_normalize()
                .ok_or("`right` must not be parallel to `direction`")?;
            let [w, h] = l.size.ok_or("`size` = [width, height] is required")?;
            if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
                return Err(format!("size must be positive, got [{w}, {h}]"));
            }
            light.direction = dir.to_array();
            light.right = right.to_array();
            light.kind = LightKind::Rect { width: w, height: h };
        }
    }
    let vals = [&light.position[..], &light.color, &[light.intensity, light.range]].concat();
    if !vals.iter().all(|v| v.is_finite()) {
        return Err("values must be finite".into());
    }
    if light.intensity < 0.0 || light.color.iter().any(|&c| c < 0.0) || light.range < 0.0 {
        return Err("intensity, color and range must be non-negative".into());
    }
    let unused: Vec<&str> = [
        ("size", l.size.is_some() && l.kind != LightKindToml::Rect),
        ("right", l.right.is_some() && l.kind != LightKindToml::Rect),
        ("direction", l.direction.is_some() && l.kind == LightKindToml::Point),
        ("position", l.position.is_some() && l.kind == LightKindToml::Directional),
        ("inner_cone_degrees", l.inner_cone_degrees.is_some() && l.kind != LightKindToml::Spot),
        ("outer_cone_degrees", l.outer_cone_degrees.is_some() && l.kind != LightKindToml::Spot),
    ]
    .into_iter()
    .filter_map(|(k, on)| on.then_some(k))
    .collect();
    if !unused.is_empty() {
        return Err(format!("{} do(es) not apply to this kind of light", unused.join(", ")));
    }
    Ok(light)
}
