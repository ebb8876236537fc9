//! `KHR_materials_clearcoat`: a clear, glossy layer over the material (car paint, lacquer,
//! varnish). The format stores its strength and roughness and their textures (format 1.8,
//! FORMAT.md "Materials"); every technique shades it as the extension defines (a GGX lobe of index
//! of refraction 1.5 over the base, which keeps what the coat's Fresnel does not reflect; the
//! raster frame approximates, docs/compiler.md). What is lost, said in a warning: the coat's own
//! normal map (`clearcoatNormalTexture`: the coat takes the surface's interpolated normal).
//!
//! The gltf crate does not parse this extension, so its JSON is read here; being an extension's
//! payload, nothing in it can fail the import: a field of the wrong type, or a texture that does
//! not exist, is named in a warning and left out.

use ::gltf::Texture;
use kiln_format::sections::GpuMaterial;
use serde_json::{Map, Value};

use super::{Importer, UvMapping};
use crate::exit::CliResult;

/// The extension's name.
const NAME: &str = "KHR_materials_clearcoat";

/// A texture reference of the coat: the texture and how it maps texture coordinates.
type TextureRef<'a> = Option<(Texture<'a>, UvMapping)>;

impl<'a> Importer<'a> {
    /// Reads material `m`'s clear coat (if any) into `gpu`'s factors; returns the references of
    /// its strength and roughness textures, for the caller to load and check with the others.
    pub(super) fn clearcoat(
        &mut self,
        at: &str,
        m: &::gltf::Material<'_>,
        gpu: &mut GpuMaterial,
    ) -> CliResult<[TextureRef<'a>; 2]> {
        let Some(value) = m.extension_value(NAME) else {
            return Ok([None, None]);
        };
        let Some(coat) = value.as_object() else {
            self.scene.warn(format!("{at}: {NAME} is not a JSON object; the material has no clear coat"));
            return Ok([None, None]);
        };
        let factor = self.number(at, coat, "clearcoatFactor", 0.0);
        let [factor] = self.physical(at, &format!("{NAME}.clearcoatFactor"), [factor], 0.0, 1.0)?;
        let roughness = self.number(at, coat, "clearcoatRoughnessFactor", 0.0);
        let [roughness] =
            self.physical(at, &format!("{NAME}.clearcoatRoughnessFactor"), [roughness], 0.0, 1.0)?;
        if coat.contains_key("clearcoatNormalTexture") {
            self.scene.warn(format!(
                "{at}: {NAME}'s clearcoatNormalTexture is not applied (the coat takes the surface's \
                 interpolated normal)"
            ));
        }
        if factor == 0.0 {
            return Ok([None, None]);
        }
        gpu.clearcoat = factor;
        gpu.clearcoat_roughness = roughness;
        Ok([
            self.texture_ref(at, coat, "clearcoatTexture"),
            self.texture_ref(at, coat, "clearcoatRoughnessTexture"),
        ])
    }

    /// The number `coat[key]`, `default` when absent; a value that is not a number is warned
    /// about and replaced by `default`.
    fn number(&mut self, at: &str, coat: &Map<String, Value>, key: &str, default: f32) -> f32 {
        match coat.get(key) {
            None => default,
            Some(Value::Number(n)) => n.as_f64().map_or(default, |v| v as f32),
            Some(other) => {
                self.scene.warn(format!("{at}: {NAME}.{key} is {other}, not a number; {default} is used"));
                default
            }
        }
    }

    /// The texture reference `coat[key]` (glTF's textureInfo: `index`, optional `texCoord` and
    /// `KHR_texture_transform`), if it names a texture of the file.
    fn texture_ref(&mut self, at: &str, coat: &Map<String, Value>, key: &str) -> TextureRef<'a> {
        let info = coat.get(key)?;
        let doc = self.doc;
        let count = doc.textures().len();
        let index = info.get("index").and_then(Value::as_u64).filter(|&i| i < count as u64);
        let tex_coord = match info.get("texCoord") {
            None => Some(0),
            Some(v) => v.as_u64().and_then(|t| u32::try_from(t).ok()),
        };
        let (Some(index), Some(tex_coord)) = (index, tex_coord) else {
            self.scene.warn(format!(
                "{at}: {NAME}.{key} {info} does not name one of the file's {count} textures with a valid \
                 texCoord; it is not applied"
            ));
            return None;
        };
        let texture = doc.textures().nth(index as usize)?;
        let transform = info.get("extensions").and_then(|e| e.get("KHR_texture_transform"));
        Some((texture, UvMapping::from_json(tex_coord, transform)))
    }
}
