//! Image decoding for textures: any failure becomes a warning and a neutral placeholder.

use crate::ir::{Texture, TextureRole};
use kiln_format::manifest::Wrap;

/// What an importer knows of a texture before its image is decoded.
#[derive(Debug, Clone)]
pub struct TextureRequest {
    /// Name for messages and the manifest.
    pub name: String,
    /// Encoded image bytes, or the reason they could not be had.
    pub bytes: Result<Vec<u8>, String>,
    /// Role.
    pub role: TextureRole,
    /// Wrap along u.
    pub wrap_u: Wrap,
    /// Wrap along v.
    pub wrap_v: Wrap,
    /// Linear magnification.
    pub mag_linear: bool,
}

/// Decodes every request in parallel; failures give a 1×1 placeholder and a warning.
pub fn decode_all(requests: Vec<TextureRequest>) -> (Vec<Texture>, Vec<String>) {
    use rayon::prelude::*;
    let decoded: Vec<(Texture, Option<String>)> = requests.into_par_iter().map(decode).collect();
    let mut warnings = Vec::new();
    let textures = decoded
        .into_iter()
        .map(|(t, w)| {
            warnings.extend(w);
            t
        })
        .collect();
    (textures, warnings)
}

fn decode(r: TextureRequest) -> (Texture, Option<String>) {
    let result = r.bytes.and_then(|bytes| super::files::decode_image(&bytes));
    let texture = |width, height, rgba| Texture {
        name: r.name.clone(),
        width,
        height,
        rgba,
        role: r.role,
        wrap_u: r.wrap_u,
        wrap_v: r.wrap_v,
        mag_linear: r.mag_linear,
    };
    match result {
        Ok(img) => {
            let rgba = img.into_rgba8();
            let (w, h) = rgba.dimensions();
            (texture(w, h, rgba.into_raw()), None)
        }
        Err(why) => (
            texture(1, 1, r.role.placeholder().to_vec()),
            Some(format!("image '{}': {why}; a neutral placeholder is used", r.name)),
        ),
    }
}
