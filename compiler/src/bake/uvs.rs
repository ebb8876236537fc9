//! The texture-coordinate stage.

use kiln_format::sections::UVS;

use super::{BakeContext, Sections};

/// Texture coordinates per vertex.
pub fn stage(ctx: &BakeContext) -> Sections {
    let mut out = Sections::default();
    out.push(UVS, 0, bytemuck::cast_slice(&ctx.scene.uvs).to_vec());
    out
}
