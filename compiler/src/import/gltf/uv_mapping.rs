//! How a material's textures read texture coordinates: the set and the `KHR_texture_transform`
//! the importer bakes into the stored coordinates.

use serde_json::Value;

/// How a material's textures map a primitive's texture coordinates: the set they read and the
/// `KHR_texture_transform` they apply (baked into the stored coordinates, which the format holds
/// one set of).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct UvMapping {
    /// `TEXCOORD_n`.
    pub(super) set: u32,
    /// u' = m[0]·u + m[1]·v + m[2], v' = m[3]·u + m[4]·v + m[5].
    pub(super) matrix: [f32; 6],
}

impl UvMapping {
    pub(super) const IDENTITY: [f32; 6] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

    /// The mapping of a texture reference: its set, or the transform's override of it, and the
    /// transform's offset · rotation · scale (glTF's `KHR_texture_transform`).
    pub(super) fn of(tex_coord: u32, transform: Option<::gltf::texture::TextureTransform>) -> UvMapping {
        let Some(t) = transform else { return UvMapping { set: tex_coord, matrix: Self::IDENTITY } };
        Self::transformed(t.tex_coord().unwrap_or(tex_coord), t.offset(), t.rotation(), t.scale())
    }

    /// The mapping of a texture reference read from JSON (an extension's textureInfo, which the
    /// gltf crate does not parse): set `tex_coord`, through the `KHR_texture_transform` object
    /// `transform` if any. Fields of the wrong type read as the extension's defaults.
    pub(super) fn from_json(tex_coord: u32, transform: Option<&Value>) -> UvMapping {
        let Some(t) = transform else { return UvMapping { set: tex_coord, matrix: Self::IDENTITY } };
        let pair = |k: &str, default: [f32; 2]| match t.get(k).and_then(Value::as_array) {
            Some(a) if a.len() == 2 && a.iter().all(Value::is_number) => {
                [a[0].as_f64().unwrap_or(0.0) as f32, a[1].as_f64().unwrap_or(0.0) as f32]
            }
            _ => default,
        };
        let rotation = t.get("rotation").and_then(Value::as_f64).unwrap_or(0.0) as f32;
        let set = t.get("texCoord").and_then(Value::as_u64).and_then(|v| u32::try_from(v).ok());
        Self::transformed(
            set.unwrap_or(tex_coord),
            pair("offset", [0.0; 2]),
            rotation,
            pair("scale", [1.0; 2]),
        )
    }

    /// Set `set` through the transform of offset `[ox, oy]`, rotation `r` and scale `[sx, sy]`.
    fn transformed(set: u32, [ox, oy]: [f32; 2], r: f32, [sx, sy]: [f32; 2]) -> UvMapping {
        let (sn, c) = r.sin_cos();
        UvMapping {
            set,
            // translation · rotation · scale as the extension's GLSL writes them (column-major
            // `mat3(cos, sin, 0, -sin, cos, 0, 0, 0, 1)`).
            matrix: [c * sx, -sn * sy, ox, sn * sx, c * sy, oy],
        }
    }

    pub(super) fn apply(&self, uv: [f32; 2]) -> [f32; 2] {
        let m = &self.matrix;
        [m[0] * uv[0] + m[1] * uv[1] + m[2], m[3] * uv[0] + m[4] * uv[1] + m[5]]
    }
}
