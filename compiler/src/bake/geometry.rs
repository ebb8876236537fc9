//! The geometry stage: vertices, triangles in BVH leaf order, and each triangle's material.

use kiln_format::sections::{TRIANGLE_MATERIALS, TRIANGLES, VERTICES};

use super::{BakeContext, Sections};

/// Vertices as imported; triangles and their materials in the BVH's leaf order.
pub fn stage(ctx: &BakeContext) -> Sections {
    let mut out = Sections::default();
    out.push(VERTICES, 0, bytemuck::cast_slice(&ctx.scene.vertices).to_vec());
    out.push(TRIANGLES, 0, bytemuck::cast_slice(&ctx.triangles).to_vec());
    out.push(TRIANGLE_MATERIALS, 0, bytemuck::cast_slice(&ctx.triangle_materials).to_vec());
    out
}
