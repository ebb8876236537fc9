//! Exact, conservative geometry of the voxel and line-space bakes, in double precision and
//! grid-local coordinates (cells are unit cubes).
//!
//! **Triangle vs. shaft.** The shaft of patches P (on face a) and Q (on face b) is the convex hull
//! of P ∪ Q = { (1 − s)·x + s·y : x ∈ P, y ∈ Q, s ∈ [0, 1] } = ∪ₛ B(s), where B(s) =
//! (1 − s)·P ⊕ s·Q is an axis-aligned box whose centre and half-extents are affine in s (P and
//! Q are axis-aligned rectangles). A box and a triangle intersect iff their projections overlap on
//! 13 axes (the three box axes, the triangle normal, and the nine cross products of box axes with
//! triangle edges: Akenine-Möller 2001). On each axis the overlap condition is a pair of affine
//! inequalities in s, so the shaft meets the triangle iff the intersection of 26 half-lines with
//! [0, 1] is non-empty: an exact test in O(1). Widening every box by the grid margin makes it
//! conservative against the rounding of the single-precision ray–triangle test.

use glam::DVec3;

/// A triangle prepared for overlap tests: its 13 separating axes and its projection on each.
#[derive(Debug, Clone)]
pub struct Prepared {
    v: [DVec3; 3],
    normal: DVec3,
    plane: f64,
    /// The 13 axes in structure-of-arrays form, padded to 16 lanes with neutral ones
    /// (L = 0, interval [−1, 1]), so that the sweep test vectorises.
    lanes: Lanes,
}

const LANES: usize = 16;

#[derive(Debug, Clone)]
struct Lanes {
    l: [[f64; LANES]; 3],
    a: [[f64; LANES]; 3],
    l1: [f64; LANES],
    t0: [f64; LANES],
    t1: [f64; LANES],
}

impl Prepared {
    /// Prepares the triangle with grid-local corners `v`.
    pub fn new(v: [DVec3; 3]) -> Prepared {
        let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
        let normal = e[0].cross(e[1]);
        let mut axes = vec![DVec3::X, DVec3::Y, DVec3::Z, normal];
        for b in [DVec3::X, DVec3::Y, DVec3::Z] {
            for ei in e {
                axes.push(b.cross(ei));
            }
        }
        let mut lanes = Lanes {
            l: [[0.0; LANES]; 3],
            a: [[0.0; LANES]; 3],
            l1: [0.0; LANES],
            t0: [-1.0; LANES],
            t1: [1.0; LANES],
        };
        for (i, l) in axes.into_iter().enumerate() {
            let p = [l.dot(v[0]), l.dot(v[1]), l.dot(v[2])];
            for k in 0..3 {
                lanes.l[k][i] = l[k];
                lanes.a[k][i] = l[k].abs();
            }
            lanes.l1[i] = l.abs().element_sum();
            lanes.t0[i] = p[0].min(p[1]).min(p[2]);
            lanes.t1[i] = p[0].max(p[1]).max(p[2]);
        }
        Prepared { v, normal, plane: normal.dot(v[0]), lanes }
    }

    /// Whether the triangle meets the box `centre ± half`.
    pub fn overlaps_box(&self, centre: DVec3, half: DVec3) -> bool {
        self.overlaps_sweep(centre, DVec3::ZERO, half, DVec3::ZERO, 0.0)
    }

    /// Whether the triangle meets ∪ₛ∈[0,1] box(c0 + s·c1, h0 + s·h1 + margin).
    pub fn overlaps_sweep(&self, c0: DVec3, c1: DVec3, h0: DVec3, h1: DVec3, margin: f64) -> bool {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports the features the function is compiled for.
            return unsafe { sweep_avx2(&self.lanes, c0, c1, h0, h1, margin) };
        }
        sweep(&self.lanes, c0, c1, h0, h1, margin)
    }

    /// Whether the triangle's plane strictly separates the boxes `ca ± ha` and `cb ± hb` (a
    /// cheap necessary condition of [`Prepared::covers`]).
    pub fn separates(&self, ca: DVec3, ha: DVec3, cb: DVec3, hb: DVec3, margin: f64) -> bool {
        let n = self.normal;
        let tol = margin * n.length();
        let (da, ra) = (n.dot(ca) - self.plane, n.abs().dot(ha));
        let (db, rb) = (n.dot(cb) - self.plane, n.abs().dot(hb));
        (da - ra > tol && db + rb < -tol) || (da + ra < -tol && db - rb > tol)
    }

    /// Whether every segment from the rectangle `pa` to the rectangle `pb` (each given by its
    /// four corners) crosses the triangle, shrunk by `margin`: then every shaft between them is
    /// filled and need not be tested one by one. The plane of the triangle must separate the two
    /// rectangles strictly, and the hull's cross-section in that plane (the hull of the 16
    /// corner-to-corner crossings) must lie inside the triangle.
    pub fn covers(&self, pa: &[DVec3; 4], pb: &[DVec3; 4], margin: f64) -> bool {
        let (n, d) = (self.normal, self.plane);
        let side = |p: &DVec3| n.dot(*p) - d;
        let sa: [f64; 4] = pa.map(|p| side(&p));
        let sb: [f64; 4] = pb.map(|p| side(&p));
        let tol = margin * n.length();
        let separated = (sa.iter().all(|&x| x > tol) && sb.iter().all(|&x| x < -tol))
            || (sa.iter().all(|&x| x < -tol) && sb.iter().all(|&x| x > tol));
        if !separated {
            return false;
        }
        for (i, a) in pa.iter().enumerate() {
            for (j, b) in pb.iter().enumerate() {
                let t = sa[i] / (sa[i] - sb[j]);
                let p = *a + (*b - *a) * t;
                if !self.contains_shrunk(p, margin) {
                    return false;
                }
            }
        }
        true
    }

    /// Whether `p` (on the triangle's plane) lies inside the triangle by more than `margin`.
    fn contains_shrunk(&self, p: DVec3, margin: f64) -> bool {
        (0..3).all(|k| {
            let e = self.v[(k + 1) % 3] - self.v[k];
            // Signed distance of p from edge k, positive inside.
            let inward = self.normal.cross(e);
            let len = inward.length();
            len > 0.0 && inward.dot(p - self.v[k]) / len > margin * 2.0
        })
    }
}

/// The sweep test. On each axis, the separation of the box B(s) from the triangle (box minimum
/// minus triangle maximum, and triangle minimum minus box maximum) is affine in s; its values at
/// s = 0 (patch P) and s = 1 (patch Q) are computed for all lanes at once. A separation positive at
/// both ends separates every B(s); one positive at one end only excludes the s beyond its root.
/// The boxes meet the triangle iff the remaining interval of s is non-empty. Divisions happen
/// only for the few separations that change sign.
#[inline(always)]
fn sweep(l: &Lanes, c0: DVec3, c1: DVec3, h0: DVec3, h1: DVec3, margin: f64) -> bool {
    let mut f0 = [0.0f64; 2 * LANES];
    let mut f1 = [0.0f64; 2 * LANES];
    for i in 0..LANES {
        let m0 = l.l[0][i] * c0.x + l.l[1][i] * c0.y + l.l[2][i] * c0.z;
        let m1 = l.l[0][i] * c1.x + l.l[1][i] * c1.y + l.l[2][i] * c1.z;
        let r0 = l.a[0][i] * h0.x + l.a[1][i] * h0.y + l.a[2][i] * h0.z + margin * l.l1[i];
        let r1 = l.a[0][i] * h1.x + l.a[1][i] * h1.y + l.a[2][i] * h1.z;
        f0[2 * i] = m0 - r0 - l.t1[i];
        f1[2 * i] = m0 + m1 - r0 - r1 - l.t1[i];
        f0[2 * i + 1] = l.t0[i] - m0 - r0;
        f1[2 * i + 1] = l.t0[i] - m0 - m1 - r0 - r1;
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for j in 0..2 * LANES {
        let (a, b) = (f0[j], f1[j]);
        if a > 0.0 || b > 0.0 {
            if a > 0.0 && b > 0.0 {
                return false;
            }
            let root = a / (a - b);
            if a > 0.0 {
                lo = lo.max(root);
            } else {
                hi = hi.min(root);
            }
        }
    }
    lo <= hi
}

/// [`sweep`] compiled for AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn sweep_avx2(l: &Lanes, c0: DVec3, c1: DVec3, h0: DVec3, h1: DVec3, margin: f64) -> bool {
    sweep(l, c0, c1, h0, h1, margin)
}

/// The triangle clipped to the box [lo, hi] (Sutherland–Hodgman); empty if they do not meet.
pub fn clip_to_box(v: [DVec3; 3], lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    let mut poly: Vec<DVec3> = v.to_vec();
    for axis in 0..3 {
        for (bound, keep_below) in [(lo[axis], false), (hi[axis], true)] {
            if poly.is_empty() {
                return poly;
            }
            let inside = |p: &DVec3| if keep_below { p[axis] <= bound } else { p[axis] >= bound };
            let mut out = Vec::with_capacity(poly.len() + 2);
            for i in 0..poly.len() {
                let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                let (ia, ib) = (inside(&a), inside(&b));
                if ia {
                    out.push(a);
                }
                if ia != ib {
                    let t = (bound - a[axis]) / (b[axis] - a[axis]);
                    let mut p = a + (b - a) * t;
                    p[axis] = bound;
                    out.push(p);
                }
            }
            poly = out;
        }
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random sampling of hull points: any sampled point inside the triangle's slab-thin
    /// neighbourhood must be found by the exact test (it may find more: it is exact, sampling is not).
    #[test]
    fn sweep_test_agrees_with_dense_sampling() {
        let mut state = 12345u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut agree = 0;
        for _ in 0..300 {
            let v = [0; 3].map(|_| DVec3::new(rnd(), rnd(), rnd()));
            let tri = Prepared::new(v);
            // P on face z = 0, Q on face x = 1: random rectangles.
            let (pu, pv) = (rnd() * 0.8, rnd() * 0.8);
            let (qu, qv) = (rnd() * 0.8, rnd() * 0.8);
            let p_lo = DVec3::new(pu, pv, 0.0);
            let p_hi = DVec3::new(pu + 0.2, pv + 0.2, 0.0);
            let q_lo = DVec3::new(1.0, qu, qv);
            let q_hi = DVec3::new(1.0, qu + 0.2, qv + 0.2);
            let (ca, ha) = ((p_lo + p_hi) * 0.5, (p_hi - p_lo) * 0.5);
            let (cb, hb) = ((q_lo + q_hi) * 0.5, (q_hi - q_lo) * 0.5);
            let exact = tri.overlaps_sweep(ca, cb - ca, ha, hb - ha, 0.0);
            // Sample segments between the patches; a segment crossing the triangle proves overlap.
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            let mut sampled = false;
            for _ in 0..4000 {
                let x = p_lo + (p_hi - p_lo) * DVec3::new(rnd(), rnd(), 0.0);
                let y = q_lo + (q_hi - q_lo) * DVec3::new(0.0, rnd(), rnd());
                let (dx, dy) = (n.dot(x - v[0]), n.dot(y - v[0]));
                if dx * dy <= 0.0 && dx != dy {
                    let p = x + (y - x) * (dx / (dx - dy));
                    let inside = (0..3).all(|k| n.dot((v[(k + 1) % 3] - v[k]).cross(p - v[k])) >= 0.0);
                    if inside {
                        sampled = true;
                        break;
                    }
                }
            }
            assert!(!sampled || exact, "sampling found an intersection the exact test missed: {v:?}");
            agree += (sampled == exact) as u32;
        }
        assert!(agree > 280, "exact and sampled tests disagree too often: {agree}/300");
    }

    #[test]
    fn clipping_keeps_inside_parts() {
        let v = [DVec3::new(-1.0, 0.5, 0.5), DVec3::new(2.0, 0.5, 0.5), DVec3::new(0.5, 2.0, 0.5)];
        let poly = clip_to_box(v, DVec3::ZERO, DVec3::ONE);
        assert!(poly.len() >= 3);
        assert!(poly.iter().all(|p| p.cmpge(DVec3::ZERO).all() && p.cmple(DVec3::ONE).all()));
        assert!(
            clip_to_box(
                [DVec3::splat(2.0), DVec3::splat(3.0), DVec3::new(2.0, 3.0, 2.0)],
                DVec3::ZERO,
                DVec3::ONE
            )
            .is_empty()
        );
    }
}
