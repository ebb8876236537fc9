//! The per-vertex attribute stages besides position and normal: texture coordinates and
//! vertex colours.

use kiln_format::sections::{COLORS, UVS};

use super::{BakeContext, Sections};

/// Texture coordinates per vertex.
pub fn stage(ctx: &BakeContext) -> Sections {
    let mut out = Sections::default();
    out.push(UVS, 0, bytemuck::cast_slice(&ctx.scene.uvs).to_vec());
    out
}

/// Vertex colours per vertex (the plan runs this only when some vertex is not white).
pub fn colors(ctx: &BakeContext) -> Sections {
    let mut out = Sections::default();
    out.push(COLORS, 0, bytemuck::cast_slice(&ctx.scene.colors).to_vec());
    out
}
