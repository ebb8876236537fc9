//! The material-table stage.

use kiln_format::sections::MATERIALS;

use super::{BakeContext, Sections};

/// The GPU material table.
pub fn stage(ctx: &BakeContext) -> Sections {
    let mut out = Sections::default();
    out.push(MATERIALS, 0, bytemuck::cast_slice(&ctx.materials).to_vec());
    out
}
