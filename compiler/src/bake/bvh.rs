//! The BVH stage: obvhs builds a CWBVH; we copy its nodes into the format's own node type and
//! return the leaf order, so that triangles can be stored in it.

use kiln_format::sections::CwbvhNode;
use obvhs::BvhBuildParams;
use obvhs::triangle::Triangle;

use crate::exit::{CliError, CliResult};
use crate::settings::BvhPreset;

/// obvhs parameters of a preset (spatial splits off: see [`BvhPreset`]).
pub fn params(preset: BvhPreset) -> BvhBuildParams {
    let mut p = match preset {
        BvhPreset::Fast => BvhBuildParams::fast_build(),
        BvhPreset::Medium => BvhBuildParams::medium_build(),
        BvhPreset::Slow => BvhBuildParams::slow_build(),
    };
    p.pre_split = false;
    p
}

/// A built BVH.
#[derive(Debug, Clone)]
pub struct BuiltBvh {
    /// Nodes, root first.
    pub nodes: Vec<CwbvhNode>,
    /// `order[i]` is the input triangle stored at leaf position `i`.
    pub order: Vec<u32>,
}

/// obvhs triangles from corner positions.
pub fn triangles(corners: impl Iterator<Item = [[f32; 3]; 3]>) -> Vec<Triangle> {
    corners.map(|c| Triangle { v0: c[0].into(), v1: c[1].into(), v2: c[2].into() }).collect()
}

/// Builds the BVH over `tris`.
pub fn build(tris: &[Triangle], preset: BvhPreset) -> CliResult<BuiltBvh> {
    let mut core = std::time::Duration::ZERO;
    let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(tris, params(preset), &mut core);
    if bvh.primitive_indices.len() != tris.len() {
        return Err(CliError::input(format!(
            "BVH builder returned {} leaf references for {} triangles",
            bvh.primitive_indices.len(),
            tris.len()
        )));
    }
    let nodes = bvh
        .nodes
        .iter()
        .map(|n| CwbvhNode {
            p: n.p.to_array(),
            e: n.e,
            imask: n.imask,
            child_base_idx: n.child_base_idx,
            primitive_base_idx: n.primitive_base_idx,
            child_meta: n.child_meta,
            child_min_x: n.child_min_x,
            child_max_x: n.child_max_x,
            child_min_y: n.child_min_y,
            child_max_y: n.child_max_y,
            child_min_z: n.child_min_z,
            child_max_z: n.child_max_z,
        })
        .collect();
    Ok(BuiltBvh { nodes, order: bvh.primitive_indices })
}

/// The BVH stage: the nodes of the BVH the context built (every other stage stores triangles in
/// its leaf order).
pub fn stage(ctx: &super::BakeContext) -> super::Sections {
    let mut out = super::Sections::default();
    out.push(
        kiln_format::sections::BVH_NODES,
        0,
        bytemuck::cast_slice(&ctx.bvh.nodes).to_vec(),
        ctx.hash("bvh", &[("preset", ctx.preset())]),
    );
    out
}
