//! Environment sources: an equirectangular HDR image (Radiance `.hdr` or OpenEXR), Preetham's
//! daylight model with its sun, or the built-in studio. Each becomes the scene's
//! [`EnvironmentImage`] (radiance in every direction, row 0 the zenith, the mapping of
//! `kiln_format::environment`), which the `environment` bake stage resamples, prefilters and
//! tabulates. `docs/sidecar.md` ("[sky]") documents the sources and their units.

use std::path::{Path, PathBuf};

use glam::Vec3;
use kiln_format::environment::{texel_solid_angle, uv_to_direction};
use kiln_format::manifest::{Light, LightKind};

use super::preetham;
use crate::exit::{CliError, CliResult};
use crate::ir::{EnvironmentImage, Scene, WarningClass};

/// Smallest map accepted: below this an equirectangular map cannot resolve a hemisphere.
pub const MIN_HEIGHT: u32 = 4;
/// Width at which the analytic sources (Preetham, studio) are generated.
pub const GENERATED_WIDTH: u32 = 1024;

/// Where the environment comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum EnvironmentSpec {
    /// An equirectangular HDR image file.
    Image {
        /// The file.
        path: PathBuf,
        /// Whether a sun found in it becomes a directional light ([`extract_sun`]).
        extract_sun: bool,
    },
    /// Preetham, Shirley and Smits's daylight model (SIGGRAPH 1999) and its sun.
    Preetham {
        /// Unit direction towards the sun (y up; above the horizon).
        sun_direction: [f32; 3],
        /// Atmospheric turbidity, 2 (clear) to 10 (hazy).
        turbidity: f32,
        /// Whether the sun is added as a directional light.
        sun: bool,
    },
    /// The built-in neutral studio (documented in `docs/sidecar.md`).
    Studio,
}

/// How the source is placed: a scale on its radiance and a rotation about +y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Multiplies every radiance.
    pub intensity: f32,
    /// Rotation about +y, degrees, by the right-hand rule (counter-clockwise seen from above).
    pub rotation_degrees: f32,
}

impl Default for Placement {
    fn default() -> Placement {
        Placement { intensity: 1.0, rotation_degrees: 0.0 }
    }
}

impl EnvironmentSpec {
    /// Parses the command line's `--environment` value: `studio`, `preetham` (sun at the
    /// sidecar's default direction) or a path to an image.
    pub fn parse(value: &str) -> Result<EnvironmentSpec, String> {
        Ok(match value {
            "studio" => EnvironmentSpec::Studio,
            "preetham" => EnvironmentSpec::Preetham {
                sun_direction: preetham::DEFAULT_SUN,
                turbidity: preetham::DEFAULT_TURBIDITY,
                sun: true,
            },
            "" => return Err("give studio, preetham or the path of an .hdr or .exr image".into()),
            path => EnvironmentSpec::Image { path: PathBuf::from(path), extract_sun: true },
        })
    }
}

/// Sets `scene`'s environment from `spec` placed by `placement`; `source` names where the request
/// came from in messages. Replaces any earlier environment (and its sun); replacing the asset's own
/// (glTF `EXT_lights_image_based`) is said in a warning ([`replace_asset_environment`]). The
/// manifest's constant sky becomes the baked map's mean radiance (what a reader that ignores the
/// environment's sections shows).
pub fn apply(scene: &mut Scene, spec: &EnvironmentSpec, placement: Placement, source: &str) -> CliResult<()> {
    let bad = |msg: String| CliError::input(format!("{source}: {msg}"));
    if !(placement.intensity.is_finite() && placement.intensity >= 0.0) {
        return Err(bad(format!(
            "environment intensity {} must be finite and non-negative",
            placement.intensity
        )));
    }
    if !placement.rotation_degrees.is_finite() {
        return Err(bad("environment rotation must be finite".into()));
    }
    scene.lights.retain(|l| l.name != preetham::SUN_NAME && l.name != EXTRACTED_SUN_NAME);
    let (name, width, pixels) = match spec {
        EnvironmentSpec::Image { path, .. } => {
            let (w, pixels) = load_image(path, scene).map_err(bad)?;
            (path.display().to_string(), w, pixels)
        }
        EnvironmentSpec::Preetham { sun_direction, turbidity, sun } => {
            let model = preetham::Sky::new(Vec3::from(*sun_direction), *turbidity).map_err(bad)?;
            let pixels = generate(GENERATED_WIDTH, |d| model.radiance(d));
            if *sun {
                scene.lights.push(model.sun_light(placement.intensity));
            }
            let ground = model.ground(&pixels, GENERATED_WIDTH);
            let pixels = fill_below_horizon(pixels, GENERATED_WIDTH, ground);
            (format!("preetham (turbidity {turbidity})"), GENERATED_WIDTH, pixels)
        }
        EnvironmentSpec::Studio => ("studio".to_owned(), GENERATED_WIDTH, generate(GENERATED_WIDTH, studio)),
    };
    replace_asset_environment(scene, source, &name);
    let take_sun = matches!(spec, EnvironmentSpec::Image { extract_sun: true, .. });
    set_map(scene, Map { name, width, pixels }, placement, take_sun, source);
    Ok(())
}

/// An equirectangular radiance map in memory: linear RGB, rows of `width` (twice the row count)
/// from the zenith down, in the mapping of `kiln_format::environment`.
#[derive(Debug, Clone, PartialEq)]
pub struct Map {
    /// Where it came from, for messages, the plan and the report.
    pub name: String,
    /// Width in pixels, even; the height is half of it.
    pub width: u32,
    /// Radiance per pixel, finite and non-negative.
    pub pixels: Vec<[f32; 3]>,
}

/// Makes `map` the scene's environment: every radiance times `placement.intensity` (checked
/// finite and non-negative by the caller), a sun in it taken out as a directional light when
/// `take_sun` ([`extract_sun`], turned by `placement.rotation_degrees`), channels past what the
/// baked map holds warned about (`source` names where the map came from). The one path by which
/// every source (a file, a model, the glTF's image-based light) becomes the [`EnvironmentImage`].
pub fn set_map(scene: &mut Scene, map: Map, placement: Placement, take_sun: bool, source: &str) {
    let Map { mut name, width, mut pixels } = map;
    debug_assert!(
        width >= 2 * MIN_HEIGHT && width % 2 == 0 && pixels.len() == (width * (width / 2)) as usize
    );
    for p in &mut pixels {
        *p = p.map(|c| c * placement.intensity);
    }
    if take_sun && let Some(sun) = extract_sun(&mut pixels, width, placement.rotation_degrees) {
        name = format!(
            "{name} (sun of {:.2}° radius taken out as a directional light of {:.4})",
            (1.0 - sun.solid_angle / std::f64::consts::TAU).acos().to_degrees(),
            sun.light.intensity
        );
        scene.lights.push(sun.light);
    }
    // What E5B9G9R9 holds at most (the bake clamps beyond it).
    let limit = 511.0 / 512.0 * 65536.0;
    let clamped = pixels.iter().flatten().filter(|&&c| c > limit).count();
    if clamped > 0 {
        scene.warn(format!(
            "{source}: environment {name}: {clamped} pixel channels are brighter than 65408, what the baked map \
             holds; they are clamped (lower the intensity and raise the exposure to keep them)"
        ));
    }
    scene.environment = Some(EnvironmentImage {
        name,
        width,
        height: width / 2,
        pixels,
        rotation_degrees: placement.rotation_degrees,
    });
}

/// Called where a sidecar or the command line sets the sky (`by` names what replaces it): when
/// the environment is still the one the asset gave (glTF `EXT_lights_image_based`), a data-loss
/// warning says that it is replaced (what the file holds is then not what the asset says, as
/// `--strict` means) and the environment is dropped.
pub fn replace_asset_environment(scene: &mut Scene, source: &str, by: &str) {
    if let Some(asset) = scene.asset_environment.take() {
        scene.environment = None;
        scene.warn(format!("{source}: the sky given here ({by}) replaces the asset's environment, {asset}"));
    }
}

/// Replaces each NaN, infinite or negative channel of `pixels` by 0; returns how many there were.
pub fn zero_non_radiance(pixels: &mut [[f32; 3]]) -> u64 {
    let mut bad = 0;
    for c in pixels.iter_mut().flatten() {
        if !(c.is_finite() && *c >= 0.0) {
            bad += 1;
            *c = 0.0;
        }
    }
    bad
}

/// Reads and decodes an HDR image (recording it as an input) and checks its shape; non-finite or
/// negative pixels become 0 with a warning on `scene`.
fn load_image(path: &Path, scene: &mut Scene) -> Result<(u32, Vec<[f32; 3]>), String> {
    super::files::check_confined("environment image", path)?;
    let bytes = super::read_input(path, &mut scene.inputs).map_err(|e| e.to_string())?;
    let named = |msg: String| format!("environment image {}: {msg}", path.display());
    match image::guess_format(&bytes) {
        Ok(image::ImageFormat::Hdr | image::ImageFormat::OpenExr) => {}
        Ok(f) => {
            return Err(named(format!(
                "a {f:?} image holds no radiance beyond 1 (the sun, a lamp): give a Radiance .hdr or OpenEXR file"
            )));
        }
        Err(_) => return Err(named("neither Radiance .hdr nor OpenEXR".into())),
    }
    let img = super::files::decode_image(&bytes).map_err(named)?.to_rgb32f();
    let (w, h) = img.dimensions();
    if h < MIN_HEIGHT || w.abs_diff(2 * h) > (2 * h) / 50 {
        return Err(named(format!(
            "{w} x {h} pixels: an equirectangular map is twice as wide as tall, at least {} x {MIN_HEIGHT}",
            2 * MIN_HEIGHT
        )));
    }
    let mut pixels: Vec<[f32; 3]> = img.pixels().map(|p| p.0).collect();
    let bad = zero_non_radiance(&mut pixels);
    if bad > 0 {
        scene.warn(named(format!("{bad} pixel channels are NaN, infinite or negative; they count as black")));
    }
    // A map a few pixels off 2:1 is resampled to exactly 2:1 (rows kept, columns stretched).
    if w != 2 * h {
        scene.warn_as(
            WarningClass::DataLoss,
            named(format!("{w} x {h} pixels is not 2:1; stretched to {} x {h}", 2 * h)),
        );
        let w2 = 2 * h;
        pixels = (0..h)
            .flat_map(|y| {
                let row = &pixels[(y * w) as usize..((y + 1) * w) as usize];
                (0..w2).map(move |x| row[((x as u64 * w as u64) / w2 as u64) as usize])
            })
            .collect();
    }
    Ok((2 * h, pixels))
}

/// An analytic environment sampled at the centres of a `width` × `width / 2` map.
pub fn generate(width: u32, f: impl Fn(Vec3) -> Vec3 + Sync) -> Vec<[f32; 3]> {
    let height = width / 2;
    (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let d = uv_to_direction((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32);
            f(d).to_array()
        })
        .collect()
}

/// The rows below the horizon replaced by `ground` (a sky model has no value there).
fn fill_below_horizon(mut pixels: Vec<[f32; 3]>, width: u32, ground: Vec3) -> Vec<[f32; 3]> {
    let half = (width / 2) as usize / 2;
    for p in &mut pixels[half * width as usize..] {
        *p = ground.to_array();
    }
    pixels
}

/// The built-in studio (docs/sidecar.md): a neutral dome brightening from 0.8 at the horizon to 1
/// at the zenith over a grey floor of 0.3, a round key softbox of radiance 6 and 15° radius up
/// and to the left of −z, and a rim light of radiance 3 and 10° behind and to the right.
pub fn studio(d: Vec3) -> Vec3 {
    const KEY: Vec3 = Vec3::new(-0.5, 0.6, -0.624_5);
    const RIM: Vec3 = Vec3::new(0.6, 0.35, 0.718_6);
    let mut l = if d.y >= 0.0 { Vec3::splat(0.8 + 0.2 * d.y) } else { Vec3::splat(0.3) };
    if d.dot(KEY.normalize()) >= 15f32.to_radians().cos() {
        l = Vec3::splat(6.0);
    }
    if d.dot(RIM.normalize()) >= 10f32.to_radians().cos() {
        l = Vec3::splat(3.0);
    }
    l
}

/// Name of the directional light a sun extracted from an image becomes.
pub const EXTRACTED_SUN_NAME: &str = "sun (environment)";

/// A pixel this many times brighter than the map's median luminance can belong to a sun.
const SUN_CONTRAST: f32 = 64.0;
/// The largest solid angle a sun may cover, sr (a cap of about 3.2° radius): a bright region
/// larger than this is sky (an overcast glare), left in the map.
const SUN_MAX_SOLID_ANGLE: f64 = 0.01;

/// A sun found in an image: what the map loses and the light that replaces it.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtractedSun {
    /// The light, shining along −(the region's luminance-weighted mean direction).
    pub light: Light,
    /// Pixels replaced.
    pub pixels: usize,
    /// Solid angle of the region, sr.
    pub solid_angle: f64,
}

/// Finds a sun in an equirectangular map (rows of `width`): the connected region (4-neighbours,
/// u wrapping) around the brightest pixel of pixels brighter than [`SUN_CONTRAST`] times the
/// median luminance, when it covers at most [`SUN_MAX_SOLID_ANGLE`]. Its light above the
/// surrounding sky (the mean of the pixels bordering it) becomes a directional light of that
/// irradiance, turned by `rotation_degrees` about +y as the bake turns the map, and the region
/// takes the surrounding sky's radiance. The map keeps the rest of its light, and the total
/// arriving from the sun's direction is unchanged; what is lost is the disc's size (the light is
/// a point in direction: hard shadows, where `--sun-angle` does not widen them).
pub fn extract_sun(pixels: &mut [[f32; 3]], width: u32, rotation_degrees: f32) -> Option<ExtractedSun> {
    let height = pixels.len() as u32 / width;
    let lum = |p: &[f32; 3]| kiln_format::gpu::luminance(*p);
    let mut sample: Vec<f32> = pixels.iter().step_by(7).map(lum).collect();
    sample.sort_by(f32::total_cmp);
    let median = sample.get(sample.len() / 2).copied().unwrap_or(0.0);
    let (brightest, peak) = pixels.iter().map(lum).enumerate().max_by(|a, b| a.1.total_cmp(&b.1))?;
    let threshold = SUN_CONTRAST * median.max(1e-6);
    if !(peak > threshold) {
        return None;
    }
    let solid = |y: u32| texel_solid_angle(y, width, height);
    let mut inside = vec![false; pixels.len()];
    let mut region = vec![brightest];
    inside[brightest] = true;
    let mut border = Vec::new();
    let mut solid_angle = 0.0;
    let mut next = 0;
    while next < region.len() {
        let i = region[next];
        next += 1;
        let (x, y) = (i as u32 % width, i as u32 / width);
        solid_angle += solid(y);
        if solid_angle > SUN_MAX_SOLID_ANGLE {
            return None;
        }
        let left = (x + width - 1) % width;
        let right = (x + 1) % width;
        let mut neighbours = vec![y * width + left, y * width + right];
        if y > 0 {
            neighbours.push((y - 1) * width + x);
        }
        if y + 1 < height {
            neighbours.push((y + 1) * width + x);
        }
        for j in neighbours.into_iter().map(|j| j as usize) {
            if inside[j] {
                continue;
            }
            if lum(&pixels[j]) > threshold {
                inside[j] = true;
                region.push(j);
            } else {
                border.push(j);
            }
        }
    }
    border.sort_unstable();
    border.dedup();
    let fill = border.iter().fold(Vec3::ZERO, |s, &j| s + Vec3::from(pixels[j])) / border.len().max(1) as f32;
    let (mut irradiance, mut axis) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
    for &i in &region {
        let (x, y) = (i as u32 % width, i as u32 / width);
        let d = uv_to_direction((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32).as_dvec3();
        let excess = (Vec3::from(pixels[i]) - fill).max(Vec3::ZERO).as_dvec3() * solid(y);
        irradiance += excess;
        axis += d * kiln_format::gpu::luminance(excess.as_vec3().to_array()) as f64;
        pixels[i] = fill.to_array();
    }
    let (s, c) = (rotation_degrees as f64).to_radians().sin_cos();
    let axis = axis.normalize_or_zero();
    let axis = glam::DVec3::new(axis.x * c + axis.z * s, axis.y, -axis.x * s + axis.z * c);
    let e = irradiance.as_vec3();
    let l = kiln_format::gpu::luminance(e.to_array());
    if !(l > 0.0) || axis == glam::DVec3::ZERO {
        return None;
    }
    Some(ExtractedSun {
        light: Light {
            name: EXTRACTED_SUN_NAME.into(),
            kind: LightKind::Directional,
            position: [0.0; 3],
            direction: (-axis.as_vec3()).to_array(),
            right: [0.0; 3],
            color: (e / l).to_array(),
            intensity: l,
            range: 0.0,
            casts_shadows: true,
        },
        pixels: region.len(),
        solid_angle,
    })
}
