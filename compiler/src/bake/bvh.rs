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
    if fanned(tris) {
        return median_tree(tris, preset);
    }
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
    let (nodes, order) = convert(bvh, tris);
    if depth(&nodes) <= BVH_TRAVERSAL_STACK {
        return Ok(BuiltBvh { nodes, order });
    }
    // PLOC's tree of degenerate geometry (100,000 slivers through one point, as a fanned polygon
    // makes) is as deep as it is wide. Geometry cannot make a median split deeper than log₂ of
    // its triangle count: slower to trace than PLOC's tree of ordinary geometry, never refused.
    median_tree(tris, preset)
}

/// Whether one corner position is shared by so many triangles (more than 4,096 and an eighth of
/// them) that PLOC would spend quadratic time on their nested boxes (a 100,000-sliver fan took
/// 21 s on 2 cores, for a tree too deep to keep): such geometry goes to the median split at once.
fn fanned(tris: &[Triangle]) -> bool {
    let limit = (tris.len() / 8).max(4096);
    if tris.len() <= limit {
        return false;
    }
    let mut count: std::collections::HashMap<[u32; 3], usize> = std::collections::HashMap::new();
    for t in tris {
        for v in [t.v0, t.v1, t.v2] {
            let c = count.entry(v.to_array().map(f32::to_bits)).or_default();
            *c += 1;
            if *c > limit {
                return true;
            }
        }
    }
    false
}

/// The median split's tree ([`median_bvh2`]) in kiln's nodes, refused only if deeper than
/// readers traverse (which ⌈log₂ n⌉ levels of a binary tree, collapsed eight-wide, never are).
fn median_tree(tris: &[Triangle], preset: BvhPreset) -> CliResult<BuiltBvh> {
    let median = obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
        &median_bvh2(tris),
        params(preset).max_prims_per_leaf.clamp(1, 3),
        true,
        false,
    );
    let (nodes, order) = convert(median, tris);
    let depth = depth(&nodes);
    if depth > BVH_TRAVERSAL_STACK {
        // Written, the file would be refused by every reader.
        return Err(CliError::input(format!(
            "the BVH over these {} triangles is {depth} levels deep, more than the {BVH_TRAVERSAL_STACK} every \
             reader's traversal stack holds",
            tris.len()
        )));
    }
    Ok(BuiltBvh { nodes, order })
}

/// A binary tree split at the median of the longest axis of its triangles' centres, a triangle
/// per leaf: depth ⌈log₂ n⌉ whatever the geometry. Built with an explicit stack.
fn median_bvh2(tris: &[Triangle]) -> obvhs::bvh2::Bvh2 {
    use obvhs::aabb::Aabb;
    use obvhs::bvh2::node::Bvh2Node;
    let n = tris.len();
    let boxes: Vec<Aabb> = tris.iter().map(Triangle::aabb).collect();
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut nodes = vec![Bvh2Node::default(); (2 * n).saturating_sub(1).max(1)];
    let mut next = 1usize;
    let mut stack = vec![(0usize, 0usize, n)];
    while let Some((node, start, end)) = stack.pop() {
        let (mut bounds, mut centres) = (Aabb::empty(), Aabb::empty());
        for &i in &order[start..end] {
            bounds = bounds.union(&boxes[i as usize]);
            centres.extend(boxes[i as usize].center());
        }
        if end - start <= 1 {
            nodes[node] = Bvh2Node::new(bounds, (end - start) as u32, start as u32);
            continue;
        }
        let size = centres.max - centres.min;
        let axis = if size.x >= size.y && size.x >= size.z {
            0
        } else if size.y >= size.z {
            1
        } else {
            2
        };
        let mid = (start + end) / 2;
        order[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            boxes[a as usize].center_axis(axis).total_cmp(&boxes[b as usize].center_axis(axis))
        });
        nodes[node] = Bvh2Node::new(bounds, 0, next as u32);
        stack.push((next, start, mid));
        stack.push((next + 1, mid, end));
        next += 2;
    }
    obvhs::bvh2::Bvh2 {
        nodes,
        primitive_indices: order,
        children_are_ordered_after_parents: true,
        ..Default::default()
    }
}

/// kiln's nodes and leaf order from obvhs's compressed wide BVH, boxes widened to contain their
/// triangles.
fn convert(bvh: obvhs::cwbvh::CwBvh, tris: &[Triangle]) -> (Vec<CwbvhNode>, Vec<u32>) {
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
    (nodes, bvh.primitive_indices)
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

    /// A disc of n slivers through its centre, given as triangles: PLOC's tree of it is deeper
    /// than readers traverse (checked here, so that the fallback is what is tested); the build
    /// falls back to the median split, whose tree holds every triangle once within the depth,
    /// and whose boxes contain their triangles (a ray test of the result is `kiln verify`'s).
    #[test]
    fn a_fan_of_slivers_gets_a_tree_readers_can_traverse() {
        let n = 20_000;
        let corner = |i: usize| {
            let a = std::f32::consts::TAU * i as f32 / (n + 1) as f32;
            [a.cos(), a.sin(), 0.0]
        };
        let tris = triangles((0..n).map(|i| [[0.0; 3], corner(i), corner(i + 1)]));
        let mut core = std::time::Duration::ZERO;
        let ploc = obvhs::cwbvh::builder::build_cwbvh_from_tris(&tris, params(BvhPreset::Medium), &mut core);
        let (ploc_nodes, _) = convert(ploc, &tris);
        assert!(depth(&ploc_nodes) > BVH_TRAVERSAL_STACK, "PLOC's depth {}", depth(&ploc_nodes));
        let built = build(&tris, BvhPreset::Medium).expect("the fan builds");
        assert!(depth(&built.nodes) <= BVH_TRAVERSAL_STACK, "depth {}", depth(&built.nodes));
        let mut seen = built.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..n as u32).collect::<Vec<_>>(), "every triangle once");
        // The fan goes to the median split before PLOC spends its time; a grid of as many
        // triangles (six at a vertex) does not.
        assert!(fanned(&tris));
        let k = 100;
        let p = |i: usize, j: usize| [i as f32, j as f32, 0.0];
        let grid = triangles((0..k * k).flat_map(|c| {
            let (i, j) = (c % k, c / k);
            [[p(i, j), p(i + 1, j), p(i + 1, j + 1)], [p(i, j), p(i + 1, j + 1), p(i, j + 1)]]
        }));
        assert_eq!(grid.len(), n);
        assert!(!fanned(&grid));
    }

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
