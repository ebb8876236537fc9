//! The BVH stage: obvhs builds a CWBVH; we copy its nodes into the format's own node type and
//! return the leaf order, so that triangles can be stored in it.

use kiln_format::sections::{BVH_TRAVERSAL_STACK, CwbvhNode};
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
    // obvhs converts its binary tree by recursion as deep as the tree, which hostile geometry
    // (100,000 slivers through one vertex) makes as deep as the triangle count: on a worker's
    // 2 MiB stack that overflows and aborts. So the build runs on a thread whose stack grows with
    // the triangles (reserved, not committed, until used).
    let stack = (tris.len() as u64 * 512).clamp(8 << 20, 4 << 30) as usize;
    let bvh = std::thread::scope(|scope| {
        std::thread::Builder::new()
            .name("bvh".into())
            .stack_size(stack)
            .spawn_scoped(scope, || {
                let mut core = std::time::Duration::ZERO;
                obvhs::cwbvh::builder::build_cwbvh_from_tris(tris, params(preset), &mut core)
            })
            .map_err(|e| {
                CliError::io(format!("cannot start the BVH build with a {} MiB stack: {e}", stack >> 20))
            })?
            .join()
            .map_err(|_| {
                CliError::input("the BVH builder failed (a panic in obvhs): please report the asset")
            })
    })?;
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
        .collect::<Vec<_>>();
    let mut nodes = nodes;
    widen_to_contain(&mut nodes, tris, &bvh.primitive_indices);
    let depth = depth(&nodes);
    if depth > BVH_TRAVERSAL_STACK {
        // Written, the file would be refused by every reader.
        return Err(CliError::input(format!(
            "the BVH over these {} triangles is {depth} levels deep, more than the {BVH_TRAVERSAL_STACK} every \
             reader's traversal stack holds: the geometry is degenerate for a BVH (e.g. thousands of \
             slivers through one point, as a fanned polygon makes); re-triangulate it",
            tris.len()
        )));
    }
    Ok(BuiltBvh { nodes, order: bvh.primitive_indices })
}

/// Levels of the tree below and including the root (1 for a root of leaves).
fn depth(nodes: &[CwbvhNode]) -> usize {
    let mut deepest = 0;
    let mut stack = if nodes.is_empty() { vec![] } else { vec![(0usize, 1usize)] };
    while let Some((i, d)) = stack.pop() {
        deepest = deepest.max(d);
        let n = &nodes[i];
        // A child index past the nodes would be the builder's bug; the reader refuses it.
        stack.extend(
            (0..8)
                .filter(|&s| n.is_internal(s))
                .map(|s| (n.child_node(s) as usize, d + 1))
                .filter(|&(c, _)| c < nodes.len()),
        );
    }
    deepest
}

/// Makes every decoded child box contain its subtree's triangles exactly, as FORMAT.md promises.
/// The builder quantises outwards in real arithmetic, but `p + s·q` evaluated in f32 can land an
/// ulp or two inside the exact plane (seen in pica_pica's z planes); each such plane moves one
/// grid step outwards until the f32 decode, the one every reader does, contains the exact box, and
/// if a maximum plane would pass 255 the axis's grid step doubles (every slot of that axis
/// re-quantised). Nodes already conservative are left as they are.
fn widen_to_contain(nodes: &mut [CwbvhNode], tris: &[Triangle], order: &[u32]) {
    if nodes.is_empty() {
        return;
    }
    let leaf_box = |first: u64, count: u32| {
        let mut b = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for k in first..first + count as u64 {
            let t = &tris[order[k as usize] as usize];
            for v in [t.v0, t.v1, t.v2] {
                for a in 0..3 {
                    b.0[a] = b.0[a].min(v[a]);
                    b.1[a] = b.1[a].max(v[a]);
                }
            }
        }
        b
    };
    // Exact subtree boxes, children before parents (a child's index is always above its
    // parent's in the builder's layout; checked, falling back to leaving the node alone).
    let mut exact: Vec<Option<([f32; 3], [f32; 3])>> = vec![None; nodes.len()];
    for n in (0..nodes.len()).rev() {
        let node = nodes[n];
        let mut children = [None; 8];
        let mut all = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for (i, child) in children.iter_mut().enumerate() {
            if node.is_empty(i) {
                continue;
            }
            let b = if node.is_internal(i) {
                let c = node.child_node(i) as usize;
                match exact.get(c).copied().flatten() {
                    Some(b) if c > n => b,
                    _ => continue,
                }
            } else {
                let (first, count) = node.leaf_range(i);
                leaf_box(first, count)
            };
            for a in 0..3 {
                all.0[a] = all.0[a].min(b.0[a]);
                all.1[a] = all.1[a].max(b.1[a]);
            }
            *child = Some(b);
        }
        exact[n] = Some(all);
        conservative(&mut nodes[n], &children);
    }
}

/// Widens the quantised planes of `node` until each decoded child box contains `children[i]`.
fn conservative(node: &mut CwbvhNode, children: &[Option<([f32; 3], [f32; 3])>; 8]) {
    for a in 0..3 {
        loop {
            let s = f32::from_bits((node.e[a] as u32) << 23);
            let decode = |q: u8| node.p[a] + s * q as f32;
            let mut overflow = false;
            let (mut lo, mut hi) = planes(node, a);
            for (i, b) in children.iter().enumerate() {
                let Some((min, max)) = b else { continue };
                while decode(lo[i]) > min[a] && lo[i] > 0 {
                    lo[i] -= 1;
                }
                while decode(hi[i]) < max[a] {
                    if hi[i] == 255 {
                        overflow = true;
                        break;
                    }
                    hi[i] += 1;
                }
            }
            if !overflow || node.e[a] >= 254 {
                set_planes(node, a, lo, hi);
                break;
            }
            // Double the step: every plane of this axis halves, rounded outwards, and is checked
            // again.
            node.e[a] += 1;
            let (lo, hi) = planes(node, a);
            set_planes(node, a, lo.map(|q| q / 2), hi.map(|q| q.div_ceil(2)));
        }
    }
}

fn planes(node: &CwbvhNode, axis: usize) -> ([u8; 8], [u8; 8]) {
    match axis {
        0 => (node.child_min_x, node.child_max_x),
        1 => (node.child_min_y, node.child_max_y),
        _ => (node.child_min_z, node.child_max_z),
    }
}

fn set_planes(node: &mut CwbvhNode, axis: usize, lo: [u8; 8], hi: [u8; 8]) {
    match axis {
        0 => (node.child_min_x, node.child_max_x) = (lo, hi),
        1 => (node.child_min_y, node.child_max_y) = (lo, hi),
        _ => (node.child_min_z, node.child_max_z) = (lo, hi),
    }
}

/// The BVH stage: the nodes of the BVH the context built (every other stage stores triangles in
/// its leaf order).
pub fn stage(ctx: &super::BakeContext) -> super::Sections {
    let mut out = super::Sections::default();
    out.push(kiln_format::sections::BVH_NODES, 0, bytemuck::cast_slice(&ctx.bvh.nodes).to_vec());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_move_outwards_and_the_step_doubles_past_255() {
        // Step 1 on every axis (e = 127), origin 0: slot 0 claims [2, 255] on x.
        let mut node = CwbvhNode { e: [127; 3], child_meta: [1, 0, 0, 0, 0, 0, 0, 0], ..Default::default() };
        node.child_min_x[0] = 2;
        node.child_max_x[0] = 255;
        node.child_max_y[0] = 1;
        node.child_max_z[0] = 1;
        // The exact box reaches 1.5 below and 255.5 above: x needs a step of 2.
        let exact = Some(([1.5, 0.0, 0.0], [255.5, 1.0, 1.0]));
        let mut children = [None; 8];
        children[0] = exact;
        conservative(&mut node, &children);
        assert_eq!(node.e, [128, 127, 127]);
        assert_eq!((node.child_min_x[0], node.child_max_x[0]), (0, 128), "1.5 → 0·2, 255.5 → 128·2 = 256");
        assert_eq!((node.child_max_y[0], node.child_max_z[0]), (1, 1), "already conservative: unchanged");
    }
}
