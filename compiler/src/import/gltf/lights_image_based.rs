//! `EXT_lights_image_based` (KhronosGroup/glTF, `extensions/2.0/Vendor/EXT_lights_image_based`):
//! the image-based light a glTF scene references becomes the scene's environment, when no sidecar
//! or command line gives one (those are applied after the import and replace it, with a warning:
//! `environment::replace_asset_environment`).
//!
//! What is read: mip 0 of `specularImages` (six images, one per cube face), `rotation` and
//! `intensity`. The cube is resampled into an equirectangular map four times as wide as a face
//! (at most `--max-image-side`; larger faces are first averaged down in whole blocks), each
//! texel bilinear within the face its direction falls on, and handed to
//! [`environment::set_map`], the path every environment source takes (a sun in it is taken out as
//! a directional light, as from an `[sky] image`). Not read: the further mips (prefiltered
//! levels, which kiln bakes itself from the map) and `irradianceCoefficients` (kiln projects its
//! own irradiance harmonics from the map), so nothing in them can fail or change a compile.
//!
//! **Values.** The extension says a JPEG is a regular LDR image, a PNG with an alpha channel holds
//! RGBD (the colour divided by the alpha is the value, beyond 1 where alpha is below 1) and a PNG
//! without one LDR data. It names no transfer curve; its reference implementation does:
//! Babylon.js writes RGBD as `pow(rgb · D, 1/2.2)` with D in alpha and reads it back as
//! `pow(rgb, 2.2) / a`, reading every face through that decoder (a JPEG's alpha is 1), as Wicked
//! Engine's importer does. So kiln reads each colour channel c (0..1) as c^2.2 and divides by
//! the alpha (linear) of a PNG that has one. A Radiance `.hdr` or OpenEXR face (which the
//! extension leaves room for) is read as the linear values it holds. The values are the scene's
//! radiance (the extension calls them lux; kiln reads glTF's photometric units 1:1 as its
//! radiometric ones, as for `KHR_lights_punctual`), times `intensity`.
//!
//! **Directions.** Faces in the extension's order +X, −X, +Y, −Y, +Z, −Z, each in "the standard
//! orientation" (the OpenGL/Vulkan cube-map table: [`face_coordinates`]), "flipped about its
//! vertical axis to correspond with the way glTF references texture space": the image's top row
//! is the table's t = 1 (Babylon.js uploads the faces flipped in y, Wicked Engine reads their rows
//! bottom up). That table is left-handed and glTF's frame right-handed: the cube is read with z
//! negated ([`cube_direction`]), as Babylon.js does in a right-handed scene
//! (`REFLECTIONMAP_OPPOSITEZ`) and Wicked Engine does (it negates the imported scene's z).
//! `rotation` (a unit quaternion q, x y z w) turns the light from its own frame into the world's:
//! what the cube holds in its direction l is seen in the world's direction q·l, as a node's
//! rotation turns its content (Babylon.js turns it that way in its default, left-handed scenes:
//! "so that positive rotation is counter-clockwise").
//!
//! Being an extension's payload, nothing in it fails the import (as `clearcoat.rs`): a missing or
//! malformed field, an image index the file lacks, a face that does not decode, faces that are not
//! square or differ in size, a negative or non-finite intensity each give a warning naming the
//! file and the light, which is then ignored; a rotation that is not unit is normalised with a
//! warning (a zero or malformed one is the identity, warned); `specularImageSize` other than the
//! faces' size is warned about (the images' size is used); values that cannot be radiance (an
//! RGBD pixel with colour and alpha 0, a NaN, infinite or negative HDR channel) count as black,
//! warned. A face image outside the confinement fails the import, as a texture's does. A light
//! the scene does not reference is not read at all.

use glam::{DQuat, Quat, Vec3};
use serde_json::{Map as JsonMap, Value};

use super::Importer;
use crate::import::environment::{self, MIN_HEIGHT, Map, Placement};
use crate::import::files;

/// The extension's name.
pub(super) const NAME: &str = "EXT_lights_image_based";

/// The faces in the extension's order (the order of OpenGL's and Vulkan's cube-map layers).
const FACES: [&str; 6] = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"];

/// A rotation whose length is within this of 1 is normalised without a warning (the writer's
/// rounding).
const UNIT_TOLERANCE: f64 = 1e-3;

/// One cube face as linear values: `size` × `size`, rows from the image's top.
struct Face {
    size: u32,
    texels: Vec<[f32; 3]>,
}

impl Face {
    /// The face bilinear at (s, y) in [0, 1]²: s from its left column, y from its top row
    /// (clamped at the edges: a face is not filtered across into its neighbours).
    fn bilinear(&self, s: f32, y: f32) -> Vec3 {
        let n = self.size as f32;
        let (x, y) = ((s * n - 0.5).clamp(0.0, n - 1.0), (y * n - 0.5).clamp(0.0, n - 1.0));
        let (x0, y0) = (x.floor() as u32, y.floor() as u32);
        let (x1, y1) = ((x0 + 1).min(self.size - 1), (y0 + 1).min(self.size - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let at = |x: u32, y: u32| Vec3::from(self.texels[(y * self.size + x) as usize]);
        let top = at(x0, y0).lerp(at(x1, y0), fx);
        let bottom = at(x0, y1).lerp(at(x1, y1), fx);
        top.lerp(bottom, fy)
    }

    /// The face averaged over `k` × `k` blocks (`size` a multiple of `k`, as powers of two are,
    /// or its last rows and columns left out).
    fn reduced(self, k: u32) -> Face {
        if k <= 1 {
            return self;
        }
        let size = self.size / k;
        let texels = (0..size * size)
            .map(|i| {
                let (bx, by) = ((i % size) * k, (i / size) * k);
                let mut sum = Vec3::ZERO;
                for y in by..by + k {
                    for x in bx..bx + k {
                        sum += Vec3::from(self.texels[(y * self.size + x) as usize]);
                    }
                }
                (sum / (k * k) as f32).to_array()
            })
            .collect();
        Face { size, texels }
    }
}

/// The widest map a light becomes: `--max-image-side` (even), the bound an equirectangular image
/// file meets.
fn map_width_cap() -> u32 {
    (files::max_image_side() & !1).max(2 * MIN_HEIGHT)
}

/// What one light of the extension holds that kiln reads.
struct Light {
    /// For messages, the plan and the report.
    name: String,
    intensity: f32,
    rotation: Quat,
    faces: Vec<Face>,
}

impl Importer<'_> {
    /// Sets the scene's environment from the image-based light that the glTF's scene (the default
    /// one, else the first, as `walk_scene` reads) references, if it references one.
    pub(super) fn image_based_light(&mut self) {
        let doc = self.doc;
        let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else { return };
        let Some(reference) = scene.extension_value(NAME) else { return };
        let Some(light) = self.read_light(scene.index(), reference) else { return };
        let faces = light.faces;
        let width = (4 * faces[0].size).clamp(2 * MIN_HEIGHT, map_width_cap());
        let to_cube = light.rotation.inverse();
        let pixels = environment::generate(width, |d| {
            let (face, s, t) = face_coordinates(cube_direction(to_cube * d));
            // The image's top row is t = 1 (the extension's flip for glTF's texture space).
            faces[face].bilinear(s, 1.0 - t)
        });
        let map = Map { name: light.name, width, pixels };
        let placement = Placement { intensity: light.intensity, rotation_degrees: 0.0 };
        environment::set_map(self.scene, map, placement, true, &self.file);
        self.scene.asset_environment = self.scene.environment.as_ref().map(|e| e.name.clone());
    }

    /// The light `reference` (a scene's extension object) names, or `None` after a warning when
    /// kiln cannot use it.
    fn read_light(&mut self, scene: usize, reference: &Value) -> Option<Light> {
        let at = format!("{}: {NAME}", self.file);
        let ignored = "the light is ignored (the scene has no environment from the file)";
        let Some(index) = reference.get("light").and_then(Value::as_u64) else {
            self.scene.warn(format!(
                "{at}: scene {scene} refers to {reference}, which names no light (`light`: an index); {ignored}"
            ));
            return None;
        };
        let lights = self.doc.extension_value(NAME).and_then(|e| e.get("lights")).and_then(Value::as_array);
        let count = lights.map_or(0, Vec::len);
        let Some(light) = lights.and_then(|l| l.get(usize::try_from(index).ok()?)) else {
            self.scene.warn(format!(
                "{at}: scene {scene} names light {index}, but the file defines {count} (the root's \
                 extensions.{NAME}.lights); {ignored}"
            ));
            return None;
        };
        let at = format!("{at} light {index}");
        let Some(light) = light.as_object() else {
            self.scene.warn(format!("{at} is not a JSON object; {ignored}"));
            return None;
        };
        match self.light_fields(&at, light) {
            Ok((intensity, faces)) => {
                let rotation = self.rotation(&at, light);
                let name = match light.get("name").and_then(Value::as_str) {
                    Some(n) => format!("{at} '{n}'"),
                    None => at,
                };
                Some(Light { name, intensity, rotation, faces })
            }
            Err(why) => {
                self.scene.warn(format!("{at}: {why}; {ignored}"));
                None
            }
        }
    }

    /// The light's intensity and its mip-0 faces (decoded, square, of one size).
    fn light_fields(&mut self, at: &str, light: &JsonMap<String, Value>) -> Result<(f32, Vec<Face>), String> {
        let intensity = match light.get("intensity") {
            None => 1.0,
            Some(v) => v
                .as_f64()
                .map(|i| i as f32)
                .filter(|i| i.is_finite() && *i >= 0.0)
                .ok_or_else(|| format!("intensity {v} is not a finite number ≥ 0"))?,
        };
        let mip0 = light
            .get("specularImages")
            .and_then(Value::as_array)
            .and_then(|mips| mips.first())
            .and_then(Value::as_array)
            .filter(|faces| faces.len() == 6)
            .ok_or("specularImages[0] is not six image indices (the cube's faces +X, -X, +Y, -Y, +Z, -Z)")?;
        let images = self.doc.images().len();
        let mut faces: Vec<Face> = Vec::with_capacity(6);
        // The faces' size as decoded, and the blocks they are averaged over: a map four faces wide
        // holds at most [`map_width_cap`] texels, so finer faces are averaged down as each is
        // decoded (six faces of 4096² would take 1.2 GB in f32).
        let mut first: Option<(u32, u32)> = None;
        for (k, v) in mip0.iter().enumerate() {
            let what = format!("the {} face (specularImages[0][{k}])", FACES[k]);
            let img = v
                .as_u64()
                .and_then(|i| self.doc.images().nth(usize::try_from(i).ok()?))
                .ok_or_else(|| format!("{what} is {v}, not one of the file's {images} images"))?;
            let what = format!("{what}, image {}", img.index());
            let bytes = self.image_bytes(&img).map_err(|e| format!("{what}: {e}"))?;
            let (w, h, texels, black) = decode_face(&bytes).map_err(|e| format!("{what}: {e}"))?;
            if let Some(black) = black {
                self.scene.warn(format!("{at}: {what}: {black}"));
            }
            if w != h || w == 0 {
                return Err(format!("{what} is {w} x {h} pixels: a cube face is square, not empty"));
            }
            let &mut (n, block) =
                first.get_or_insert((w, (4 * u64::from(w)).div_ceil(u64::from(map_width_cap())) as u32));
            if w != n {
                return Err(format!(
                    "{what} is {w} x {w} pixels but the {} face {n} x {n}: the faces differ in size",
                    FACES[0]
                ));
            }
            faces.push(Face { size: w, texels }.reduced(block));
        }
        let n = first.map_or(0, |(n, _)| n);
        if let Some(v) = light.get("specularImageSize")
            && v.as_u64() != Some(u64::from(n))
        {
            self.scene.warn(format!(
                "{at}: specularImageSize {v} is not the {n} pixels of mip 0's faces; the images' size is used"
            ));
        }
        Ok((intensity, faces))
    }

    /// The light's `rotation`, normalised; the identity when absent, or (warned) zero or malformed.
    fn rotation(&mut self, at: &str, light: &JsonMap<String, Value>) -> Quat {
        let Some(v) = light.get("rotation") else { return Quat::IDENTITY };
        let q = v.as_array().filter(|a| a.len() == 4).and_then(|a| {
            let c: Option<Vec<f64>> = a.iter().map(Value::as_f64).collect();
            c.map(|c| DQuat::from_xyzw(c[0], c[1], c[2], c[3]))
        });
        let Some(q) = q else {
            self.scene
                .warn(format!("{at}: rotation {v} is not four numbers (x, y, z, w); the identity is used"));
            return Quat::IDENTITY;
        };
        let length = q.length();
        if !(length.is_finite() && length > 0.0) {
            self.scene
                .warn(format!("{at}: rotation {v} has length {length}, no rotation; the identity is used"));
            return Quat::IDENTITY;
        }
        if (length - 1.0).abs() > UNIT_TOLERANCE {
            self.scene.warn(format!(
                "{at}: rotation {v} has length {length:.6}, not 1 (a rotation is a unit quaternion); normalised"
            ));
        }
        (q / length).as_quat()
    }
}

/// A decoded face: width, height, linear values (rows from the top; see the module's "Values"),
/// and what a warning should say of values read as black.
type Decoded = (u32, u32, Vec<[f32; 3]>, Option<String>);

/// A face image decoded as textures are ([`files::decode_image`], within `--max-image-side`).
fn decode_face(bytes: &[u8]) -> Result<Decoded, String> {
    let format = image::guess_format(bytes).ok();
    let img = files::decode_image(bytes)?;
    let (w, h) = (img.width(), img.height());
    let gamma = |c: f32| c.clamp(0.0, 1.0).powf(2.2);
    let mut black = None;
    let texels: Vec<[f32; 3]> = match format {
        Some(image::ImageFormat::Hdr | image::ImageFormat::OpenExr) => {
            let mut texels: Vec<[f32; 3]> = img.into_rgb32f().pixels().map(|p| p.0).collect();
            let bad = environment::zero_non_radiance(&mut texels);
            if bad > 0 {
                black = Some(format!("{bad} channels are NaN, infinite or negative; they count as black"));
            }
            texels
        }
        Some(image::ImageFormat::Png) if img.color().has_alpha() => {
            let mut bad = 0u64;
            let texels = img
                .into_rgba32f()
                .pixels()
                .map(|p| {
                    let [r, g, b, d] = p.0;
                    let c = [r, g, b].map(gamma);
                    if d > 0.0 {
                        c.map(|c| c / d)
                    } else {
                        bad += u64::from(c.iter().any(|&c| c > 0.0));
                        [0.0; 3]
                    }
                })
                .collect();
            if bad > 0 {
                black = Some(format!(
                    "a PNG with alpha holds RGBD (colour / alpha), but {bad} pixels have a colour and alpha 0; \
                     they count as black"
                ));
            }
            texels
        }
        _ => img.into_rgb32f().pixels().map(|p| p.0.map(gamma)).collect(),
    };
    Ok((w, h, texels, black))
}

/// Where the world's (glTF's) unit direction `l`, in the light's own frame, falls in the cube
/// map's frame: z negated, since the cube-map table is left-handed (the module's "Directions").
pub(super) fn cube_direction(l: Vec3) -> Vec3 {
    Vec3::new(l.x, l.y, -l.z)
}

/// The face (0..6 in the extension's order) and (s, t) in [0, 1]² of cube-map direction `c`, by
/// the OpenGL 4.6 table 8.19 (Vulkan's "Cube Map Face Selection" is the same): the major axis
/// picks the face, and s = (sc / |ma| + 1) / 2, t = (tc / |ma| + 1) / 2 with
///
/// | face | sc  | tc  |
/// |------|-----|-----|
/// | +X   | −z  | −y  |
/// | −X   | +z  | −y  |
/// | +Y   | +x  | +z  |
/// | −Y   | +x  | −z  |
/// | +Z   | +x  | −y  |
/// | −Z   | −x  | −y  |
///
/// Ties go to x, then y.
pub(super) fn face_coordinates(c: Vec3) -> (usize, f32, f32) {
    let a = c.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if c.x >= 0.0 { (0, -c.z, -c.y, a.x) } else { (1, c.z, -c.y, a.x) }
    } else if a.y >= a.z {
        if c.y >= 0.0 { (2, c.x, c.z, a.y) } else { (3, c.x, -c.z, a.y) }
    } else if c.z >= 0.0 {
        (4, c.x, -c.y, a.z)
    } else {
        (5, -c.x, -c.y, a.z)
    };
    (face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0))
}
