//! Closest-hit and any-hit traversal of the compressed wide BVH.
//!
//! Box tests are conservative: decoded planes are widened by one ulp (the decoding `p + s·q`
//! rounds once; `s·q` is exact) and the slab test scales its far distance by `1 + 2γ₃` (Ize,
//! "Robust BVH Ray Traversal", JCGT 2013). So a triangle the brute-force test hits is never culled
//! by a box, and traversal gives exactly the brute-force answer up to ties in distance.

use super::{Hit, Ray, TriangleSource, intersect_triangle};
use crate::sections::{BVH_TRAVERSAL_STACK, CwbvhNode};

/// `γ₃ = 3ε / (1 − 3ε)` for f32 (ε = 2⁻²⁴).
const GAMMA3: f32 = 3.0 * (f32::EPSILON * 0.5) / (1.0 - 3.0 * (f32::EPSILON * 0.5));

/// Counters of one traversal, for benchmarks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TraversalStats {
    /// Nodes visited.
    pub nodes: u32,
    /// Triangle tests.
    pub triangles: u32,
}

/// A BVH over triangles, ready to be queried. The BVH must be valid (as checked by
/// [`crate::SceneView`]); leaves index `tris` directly.
#[derive(Debug, Clone, Copy)]
pub struct BvhQuery<'a, T: TriangleSource + ?Sized> {
    nodes: &'a [CwbvhNode],
    tris: &'a T,
}

impl<'a, T: TriangleSource + ?Sized> BvhQuery<'a, T> {
    /// A query over `nodes` (root first) and `tris` in leaf order.
    pub fn new(nodes: &'a [CwbvhNode], tris: &'a T) -> Self {
        Self { nodes, tris }
    }

    /// The closest hit in `[tmin, tmax)`.
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.traverse(ray, false, &mut TraversalStats::default())
    }

    /// The closest hit, counting work.
    pub fn closest_hit_with_stats(&self, ray: &Ray, stats: &mut TraversalStats) -> Option<Hit> {
        self.traverse(ray, false, stats)
    }

    /// Whether anything is hit in `[tmin, tmax)` (stops at the first hit).
    pub fn any_hit(&self, ray: &Ray) -> bool {
        self.traverse(ray, true, &mut TraversalStats::default()).is_some()
    }

    fn traverse(&self, ray: &Ray, any: bool, stats: &mut TraversalStats) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best: Option<Hit> = None;
        let mut tmax = ray.tmax;
        // (entry distance, node) pairs; 8 children per level at most, depth bounded by validation.
        let mut stack: Vec<(f32, u32)> = Vec::with_capacity(BVH_TRAVERSAL_STACK * 8);
        stack.push((ray.tmin, 0));
        let mut children: [(f32, u32); 8] = [(0.0, 0); 8];
        while let Some((entry, index)) = stack.pop() {
            if entry > tmax {
                continue;
            }
            let node = &self.nodes[index as usize];
            stats.nodes += 1;
            let mut internal = 0;
            for slot in 0..8 {
                if node.is_empty(slot) {
                    continue;
                }
                let Some(t_entry) = slab(node, slot, ray, tmax) else { continue };
                if node.is_internal(slot) {
                    children[internal] = (t_entry, node.child_node(slot) as u32);
                    internal += 1;
                } else {
                    let (first, count) = node.leaf_range(slot);
                    for t in first..first + count as u64 {
                        stats.triangles += 1;
                        if let Some(h) = intersect_triangle(ray, self.tris.corners(t as usize), tmax) {
                            let hit = Hit { t: h.t, triangle: t as u32, u: h.u, v: h.v };
                            if any {
                                return Some(hit);
                            }
                            tmax = h.t;
                            best = Some(hit);
                        }
                    }
                }
            }
            // Push far to near so that the nearest child is visited first.
            let c = &mut children[..internal];
            c.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
            stack.extend_from_slice(c);
        }
        best
    }
}

/// Conservative slab test of child `slot`; the entry distance if the box is hit within
/// `[ray.tmin, tmax]`.
#[inline]
fn slab(node: &CwbvhNode, slot: usize, ray: &Ray, tmax: f32) -> Option<f32> {
    let (lo, hi) = node.child_box(slot);
    let mut t_enter = ray.tmin;
    let mut t_exit = tmax;
    for a in 0..3 {
        let (lo, hi) = (lo[a].next_down(), hi[a].next_up());
        let o = ray.origin[a];
        let inv = ray.inv_direction[a];
        let t0 = (lo - o) * inv;
        let t1 = (hi - o) * inv;
        if t0.is_nan() || t1.is_nan() {
            // Zero direction component with the origin on a plane (0 · inf): the ray runs
            // inside this slab iff the origin is within the closed interval.
            if lo <= o && o <= hi {
                continue;
            }
            return None;
        }
        t_enter = t_enter.max(t0.min(t1));
        t_exit = t_exit.min(t0.max(t1) * (1.0 + 2.0 * GAMMA3));
    }
    (t_enter <= t_exit).then_some(t_enter)
}
