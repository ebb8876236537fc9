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
use kiln_format::linespace::index::{MAX_SHAFT_RES, face_axis, face_uv_axes};

/// A triangle prepared for overlap tests: its 13 separating axes and its projection on each.
#[derive(Debug, Clone)]
pub struct Prepared {
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
        Prepared { lanes }
    }

    /// Whether the triangle meets the box `centre ± half`.
    pub fn overlaps_box(&self, centre: DVec3, half: DVec3) -> bool {
        self.overlaps_sweep(centre, DVec3::ZERO, half, DVec3::ZERO, 0.0)
    }

    /// Whether the triangle meets ∪ₛ∈[0,1] box(c0 + s·c1, h0 + s·h1 + margin).
    pub fn overlaps_sweep(&self, c0: DVec3, c1: DVec3, h0: DVec3, h1: DVec3, margin: f64) -> bool {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports the features the function is compiled for.
            return unsafe { sweep_avx2(&self.lanes, c0, c1, h0, h1, margin) };
        }
        sweep(&self.lanes, c0, c1, h0, h1, margin)
    }

    /// The triangle's separations for the shafts of face pair (`fa`, `fb`) at resolution `n`,
    /// ready for [`PairAxes::shafts_from`].
    pub fn pair_axes(&self, fa: u32, fb: u32, n: u32, margin: f64) -> PairAxes {
        let l = &self.lanes;
        let s = 1.0 / n as f64;
        let half = 0.5 * s;
        let mut p = PairAxes {
            a: [[0.0; LANES]; 2],
            a_du: [0.0; LANES],
            a_dv: [0.0; LANES],
            b: [[0.0; LANES]; 2],
            b_du: [0.0; LANES],
            b_dv: [0.0; LANES],
        };
        // A patch of face f at indices (u, v) is the box with centre (f mod 2) on f's axis and
        // (index + 1/2)·s on the other two, half extent s/2 on those. So on every axis the
        // centre's projection is affine in (u, v) and the box's radius is one number.
        for (face, sep, du, dv) in
            [(fa, &mut p.a, &mut p.a_du, &mut p.a_dv), (fb, &mut p.b, &mut p.b_du, &mut p.b_dv)]
        {
            let (j, plane) = (face_axis(face), (face % 2) as f64);
            let (ua, va) = face_uv_axes(face);
            for i in 0..LANES {
                let lv = [l.l[0][i], l.l[1][i], l.l[2][i]];
                let av = [l.a[0][i], l.a[1][i], l.a[2][i]];
                let k = lv[j] * plane + (lv[ua] + lv[va]) * half;
                let r = (av[ua] + av[va]) * half + margin * l.l1[i];
                // Positive: separated. Box minimum minus triangle maximum is k − r − t1 plus
                // (u·du + v·dv); triangle minimum minus box maximum is t0 − k − r minus it.
                sep[0][i] = k - r - l.t1[i];
                sep[1][i] = l.t0[i] - k - r;
                du[i] = lv[ua] * s;
                dv[i] = lv[va] * s;
            }
        }
        p
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

/// One triangle's separations from the patches of two faces (see [`Prepared::pair_axes`]): on
/// each of the 16 lanes (13 axes and padding) and for each of the two sides, `a[side] ±
/// (u·a_du + v·a_dv)` for the patch (u, v) of face a (+ for side 0), the same with `b` for face b.
#[derive(Debug, Clone)]
pub struct PairAxes {
    a: [[f64; LANES]; 2],
    a_du: [f64; LANES],
    a_dv: [f64; LANES],
    b: [[f64; LANES]; 2],
    b_du: [f64; LANES],
    b_dv: [f64; LANES],
}

impl PairAxes {
    /// The shafts from patch (`au`, `av`) of face a to the patches `rect` = [u0, u1) × [v0, v1)
    /// of face b (at most 64) that meet the triangle, as a bit mask: bit (u − u0)·(v1 − v0) +
    /// (v − v0) stands for patch (u, v). The sweep test of [`Prepared::overlaps_sweep`] for
    /// every shaft at once.
    ///
    /// At the a end (s = 0) each axis's separation is one number for all the shafts; at the b
    /// end it is affine in the patch indices, so its extremes over the rectangle are at corners:
    /// an axis that separates the a end and every b corner rejects all shafts, one that separates
    /// neither end anywhere is skipped, and only the rest run per shaft, comparing the roots as
    /// fractions, without dividing.
    pub fn shafts_from(&self, au: u32, av: u32, rect: [u32; 4]) -> u64 {
        debug_assert!((rect[1] - rect[0]) * (rect[3] - rect[2]) <= 64);
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports the features the function is compiled for.
            return unsafe { shafts_avx2(self, au, av, rect) };
        }
        shafts(self, au, av, rect)
    }
}

/// The shafts of a target rectangle, shared by [`shafts`] and its AVX2 twin: the rectangle's
/// width, its number of patches and the mask of them all; `None` when it is empty.
#[inline(always)]
fn rect_shafts(rect: [u32; 4]) -> Option<(usize, usize, u64)> {
    let [u0, u1, v0, v1] = rect;
    if u0 >= u1 || v0 >= v1 {
        return None;
    }
    let w = (v1 - v0) as usize;
    let count = (u1 - u0) as usize * w;
    Some((w, count, if count == 64 { u64::MAX } else { (1u64 << count) - 1 }))
}

/// The patch indices of shaft `k` of the rectangle (padding beyond `count` repeats the last).
#[inline(always)]
fn shaft_patch(rect: [u32; 4], w: usize, count: usize, k: usize) -> (f64, f64) {
    let (du, dv) = window_offset(k.min(count - 1) as u32, w as u32);
    ((rect[0] + du) as f64, (rect[2] + dv) as f64)
}

/// Bit `k` of a rectangle `w` patches wide (the bit layout of [`PairAxes::shafts_from`]) as its
/// (row, column) offset, from a table: two integer divisions per shaft cost more than the rest
/// of a small rectangle's test.
#[inline(always)]
pub fn window_offset(k: u32, w: u32) -> (u32, u32) {
    let (row, column) = WINDOW_OFFSETS[w as usize][k as usize];
    (row as u32, column as u32)
}

const WINDOW_OFFSETS: [[(u8, u8); 64]; MAX_SHAFT_RES as usize + 1] = {
    let mut t = [[(0u8, 0u8); 64]; MAX_SHAFT_RES as usize + 1];
    let mut w = 1;
    while w <= MAX_SHAFT_RES as usize {
        let mut k = 0;
        while k < 64 {
            t[w][k] = ((k / w) as u8, (k % w) as u8);
            k += 1;
        }
        w += 1;
    }
    t
};

/// The b end's separation on lane `i` of `side` as base + u·du + v·dv (negating du and dv gives
/// the same bits as subtracting for side 1).
#[inline(always)]
fn b_end(p: &PairAxes, side: usize, i: usize) -> (f64, f64, f64) {
    if side == 0 { (p.b[0][i], p.b_du[i], p.b_dv[i]) } else { (p.b[1][i], -p.b_du[i], -p.b_dv[i]) }
}

/// See [`PairAxes::shafts_from`]. Plain arithmetic (no fused multiply-adds), so that the AVX2
/// build and the portable one give the same bits.
#[inline(always)]
fn shafts(p: &PairAxes, au: u32, av: u32, rect: [u32; 4]) -> u64 {
    let Some((w, count, all)) = rect_shafts(rect) else { return 0 };
    let [u0, u1, v0, v1] = rect;
    let (au, av) = (au as f64, av as f64);
    let (bu0, bu1, bv0, bv1) = (u0 as f64, (u1 - 1) as f64, v0 as f64, (v1 - 1) as f64);
    // Per lane and side: the a end's separation and the least and greatest of the b end's.
    let mut sa = [[0.0f64; LANES]; 2];
    let mut bmin = [[0.0f64; LANES]; 2];
    let mut bmax = [[0.0f64; LANES]; 2];
    for i in 0..LANES {
        let ta = au * p.a_du[i] + av * p.a_dv[i];
        sa[0][i] = p.a[0][i] + ta;
        sa[1][i] = p.a[1][i] - ta;
        let (lu, hu) = (bu0 * p.b_du[i], bu1 * p.b_du[i]);
        let (lv, hv) = (bv0 * p.b_dv[i], bv1 * p.b_dv[i]);
        // Written as the AVX2 minimum and maximum behave.
        let lo = (if lu < hu { lu } else { hu }) + (if lv < hv { lv } else { hv });
        let hi = (if lu > hu { lu } else { hu }) + (if lv > hv { lv } else { hv });
        bmin[0][i] = p.b[0][i] + lo;
        bmax[0][i] = p.b[0][i] + hi;
        bmin[1][i] = p.b[1][i] - hi;
        bmax[1][i] = p.b[1][i] - lo;
    }
    // Which (side, lane) pairs need the per-shaft work.
    let mut active = 0u32;
    for side in 0..2 {
        for i in 0..LANES {
            let a = sa[side][i];
            if a > 0.0 && bmin[side][i] > 0.0 {
                return 0;
            }
            if a > 0.0 || bmax[side][i] > 0.0 {
                active |= 1 << (side * LANES + i);
            }
        }
    }
    if active == 0 {
        return all;
    }
    if count <= 16 {
        per_shaft::<4>(p, &sa, active, rect, w, count)
    } else {
        per_shaft::<16>(p, &sa, active, rect, w, count)
    }
}

/// The per-shaft part of [`shafts`] for the (side, lane) pairs in `active`, with room for `CAP`
/// groups of four shafts. Written without branches over the shafts, so that it vectorises.
#[inline(always)]
fn per_shaft<const CAP: usize>(
    p: &PairAxes,
    sa: &[[f64; LANES]; 2],
    mut active: u32,
    rect: [u32; 4],
    w: usize,
    count: usize,
) -> u64 {
    // Groups of four shafts; the padding repeats the last patch.
    let groups = count.div_ceil(4);
    let mut bu = [[0.0f64; 4]; CAP];
    let mut bv = [[0.0f64; 4]; CAP];
    for g in 0..groups {
        for q in 0..4 {
            (bu[g][q], bv[g][q]) = shaft_patch(rect, w, count, 4 * g + q);
        }
    }
    // Roots as fractions num/den (den > 0): the interval [lo, hi] of s each shaft leaves. A
    // shaft separated at both ends gets lo = 2 (> 1 ≥ hi), which later roots cannot lower.
    let mut lo_n = [[0.0f64; 4]; CAP];
    let mut lo_d = [[1.0f64; 4]; CAP];
    let mut hi_n = [[1.0f64; 4]; CAP];
    let mut hi_d = [[1.0f64; 4]; CAP];
    while active != 0 {
        let bit = active.trailing_zeros() as usize;
        active &= active - 1;
        let (side, i) = (bit / LANES, bit % LANES);
        let a = sa[side][i];
        let (base, du, dv) = b_end(p, side, i);
        if a > 0.0 {
            // Separated at the a end: s ≥ a/(a − b) where b ≤ 0, and no s where b > 0.
            for g in 0..groups {
                for q in 0..4 {
                    let b = base + (bu[g][q] * du + bv[g][q] * dv);
                    let both = b > 0.0;
                    let (num, den) = (if both { 2.0 } else { a }, if both { 1.0 } else { a - b });
                    let later = num * lo_d[g][q] > lo_n[g][q] * den;
                    lo_n[g][q] = if later { num } else { lo_n[g][q] };
                    lo_d[g][q] = if later { den } else { lo_d[g][q] };
                }
            }
        } else {
            // Separated at the b end only: s ≤ a/(a − b) = −a/(b − a).
            for g in 0..groups {
                for q in 0..4 {
                    let b = base + (bu[g][q] * du + bv[g][q] * dv);
                    let (num, den) = (-a, b - a);
                    let earlier = b > 0.0 && num * hi_d[g][q] < hi_n[g][q] * den;
                    hi_n[g][q] = if earlier { num } else { hi_n[g][q] };
                    hi_d[g][q] = if earlier { den } else { hi_d[g][q] };
                }
            }
        }
    }
    let mut mask = 0u64;
    for k in 0..count {
        let (g, q) = (k / 4, k % 4);
        if lo_n[g][q] * hi_d[g][q] <= hi_n[g][q] * lo_d[g][q] {
            mask |= 1 << k;
        }
    }
    mask
}

/// [`shafts`] in AVX2 intrinsics, four lanes or shafts at a time, with the same arithmetic
/// operation for operation (the same bits).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn shafts_avx2(p: &PairAxes, au: u32, av: u32, rect: [u32; 4]) -> u64 {
    use std::arch::x86_64::*;
    let Some((w, count, all)) = rect_shafts(rect) else { return 0 };
    let [u0, u1, v0, v1] = rect;
    let s = |x: f64| _mm256_set1_pd(x);
    let (zero, one, two) = (_mm256_setzero_pd(), s(1.0), s(2.0));
    let gt = |x: __m256d, y: __m256d| _mm256_cmp_pd::<_CMP_GT_OQ>(x, y);
    let (au, av) = (s(au as f64), s(av as f64));
    let (bu0, bu1, bv0, bv1) = (s(u0 as f64), s((u1 - 1) as f64), s(v0 as f64), s((v1 - 1) as f64));
    let mut sa = [[0.0f64; LANES]; 2];
    let mut reject = zero;
    let mut active = 0u32;
    for g in (0..LANES).step_by(4) {
        // SAFETY: g + 4 <= LANES, the arrays' length.
        let ld = |x: &[f64; LANES]| unsafe { _mm256_loadu_pd(x.as_ptr().add(g)) };
        let ta = _mm256_add_pd(_mm256_mul_pd(au, ld(&p.a_du)), _mm256_mul_pd(av, ld(&p.a_dv)));
        let sa0 = _mm256_add_pd(ld(&p.a[0]), ta);
        let sa1 = _mm256_sub_pd(ld(&p.a[1]), ta);
        let (bdu, bdv) = (ld(&p.b_du), ld(&p.b_dv));
        let (lu, hu) = (_mm256_mul_pd(bu0, bdu), _mm256_mul_pd(bu1, bdu));
        let (lv, hv) = (_mm256_mul_pd(bv0, bdv), _mm256_mul_pd(bv1, bdv));
        let lo = _mm256_add_pd(_mm256_min_pd(lu, hu), _mm256_min_pd(lv, hv));
        let hi = _mm256_add_pd(_mm256_max_pd(lu, hu), _mm256_max_pd(lv, hv));
        let (b0, b1) = (ld(&p.b[0]), ld(&p.b[1]));
        let (bmin0, bmax0) = (_mm256_add_pd(b0, lo), _mm256_add_pd(b0, hi));
        let (bmin1, bmax1) = (_mm256_sub_pd(b1, hi), _mm256_sub_pd(b1, lo));
        let (pa0, pa1) = (gt(sa0, zero), gt(sa1, zero));
        reject = _mm256_or_pd(reject, _mm256_and_pd(pa0, gt(bmin0, zero)));
        reject = _mm256_or_pd(reject, _mm256_and_pd(pa1, gt(bmin1, zero)));
        active |= (_mm256_movemask_pd(_mm256_or_pd(pa0, gt(bmax0, zero))) as u32) << g;
        active |= (_mm256_movemask_pd(_mm256_or_pd(pa1, gt(bmax1, zero))) as u32) << (LANES + g);
        // SAFETY: g + 4 <= LANES.
        unsafe {
            _mm256_storeu_pd(sa[0].as_mut_ptr().add(g), sa0);
            _mm256_storeu_pd(sa[1].as_mut_ptr().add(g), sa1);
        }
    }
    if _mm256_movemask_pd(reject) != 0 {
        return 0;
    }
    if active == 0 {
        return all;
    }
    // The active (side, lane) pairs in two lists, in ascending order: those separated at the a
    // end bound each shaft's interval from below, the rest from above; the two bounds are kept
    // apart, so the lists may run one after the other. Each group of four shafts then runs
    // through both with its interval in registers (updating arrays of intervals lane by lane
    // made the compiler write them with masked stores, which cost more than the arithmetic).
    // (Left uninitialised: zeroing them cost a tenth of the test.)
    let mut lower = [std::mem::MaybeUninit::<[f64; 4]>::uninit(); 2 * LANES];
    let mut upper = [std::mem::MaybeUninit::<[f64; 4]>::uninit(); 2 * LANES];
    let (mut n_lower, mut n_upper) = (0, 0);
    while active != 0 {
        let bit = active.trailing_zeros() as usize;
        active &= active - 1;
        let (side, i) = (bit / LANES, bit % LANES);
        let a = sa[side][i];
        let (base, du, dv) = b_end(p, side, i);
        // Written to both lists, kept by one (without a branch: the sign is unpredictable).
        lower[n_lower].write([a, base, du, dv]);
        upper[n_upper].write([a, base, du, dv]);
        let below = (a > 0.0) as usize;
        n_lower += below;
        n_upper += 1 - below;
    }
    let mut mask = 0u64;
    for g in 0..count.div_ceil(4) {
        let at = |q: usize| shaft_patch(rect, w, count, 4 * g + q);
        let [(a0, c0), (a1, c1), (a2, c2), (a3, c3)] = [at(0), at(1), at(2), at(3)];
        let bu = _mm256_set_pd(a3, a2, a1, a0);
        let bv = _mm256_set_pd(c3, c2, c1, c0);
        let (mut lo_n, mut lo_d, mut hi_n, mut hi_d) = (zero, one, one, one);
        for lane in &lower[..n_lower] {
            // SAFETY: the first `n_lower` entries are written above.
            let [a, base, du, dv] = unsafe { lane.assume_init() };
            // Separated at the a end: s ≥ a/(a − b) where b ≤ 0, and no s where b > 0.
            let va = s(a);
            let b = _mm256_add_pd(s(base), _mm256_add_pd(_mm256_mul_pd(bu, s(du)), _mm256_mul_pd(bv, s(dv))));
            let both = gt(b, zero);
            let num = _mm256_blendv_pd(va, two, both);
            let den = _mm256_blendv_pd(_mm256_sub_pd(va, b), one, both);
            let later = gt(_mm256_mul_pd(num, lo_d), _mm256_mul_pd(lo_n, den));
            lo_n = _mm256_blendv_pd(lo_n, num, later);
            lo_d = _mm256_blendv_pd(lo_d, den, later);
        }
        for lane in &upper[..n_upper] {
            // SAFETY: the first `n_upper` entries are written above.
            let [a, base, du, dv] = unsafe { lane.assume_init() };
            // Separated at the b end only: s ≤ a/(a − b) = −a/(b − a).
            let (va, num) = (s(a), s(-a));
            let b = _mm256_add_pd(s(base), _mm256_add_pd(_mm256_mul_pd(bu, s(du)), _mm256_mul_pd(bv, s(dv))));
            let den = _mm256_sub_pd(b, va);
            let earlier = _mm256_and_pd(
                gt(b, zero),
                _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_mul_pd(num, hi_d), _mm256_mul_pd(hi_n, den)),
            );
            hi_n = _mm256_blendv_pd(hi_n, num, earlier);
            hi_d = _mm256_blendv_pd(hi_d, den, earlier);
        }
        let ok = _mm256_cmp_pd::<_CMP_LE_OQ>(_mm256_mul_pd(lo_n, hi_d), _mm256_mul_pd(hi_n, lo_d));
        mask |= (_mm256_movemask_pd(ok) as u64) << (4 * g);
    }
    mask & all
}

/// [`sweep`] in AVX2, four lanes at a time and without branches: every separation's root is
/// computed and masked, and the interval's ends are reduced at the end. The arithmetic is the
/// scalar version's, operation for operation (no fused multiply-adds), so both give the same
/// answer bit for bit.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sweep_avx2(l: &Lanes, c0: DVec3, c1: DVec3, h0: DVec3, h1: DVec3, margin: f64) -> bool {
    use std::arch::x86_64::*;
    let s = |x: f64| _mm256_set1_pd(x);
    let (c0x, c0y, c0z) = (s(c0.x), s(c0.y), s(c0.z));
    let (c1x, c1y, c1z) = (s(c1.x), s(c1.y), s(c1.z));
    let (h0x, h0y, h0z) = (s(h0.x), s(h0.y), s(h0.z));
    let (h1x, h1y, h1z) = (s(h1.x), s(h1.y), s(h1.z));
    let m = s(margin);
    let (zero, one) = (_mm256_setzero_pd(), s(1.0));
    let (mut lo, mut hi, mut reject) = (zero, one, zero);
    for g in (0..LANES).step_by(4) {
        // SAFETY: g + 4 <= LANES, the arrays' length.
        let ld = |a: &[f64; LANES]| unsafe { _mm256_loadu_pd(a.as_ptr().add(g)) };
        let (lx, ly, lz) = (ld(&l.l[0]), ld(&l.l[1]), ld(&l.l[2]));
        let (ax, ay, az) = (ld(&l.a[0]), ld(&l.a[1]), ld(&l.a[2]));
        let (l1, t0, t1) = (ld(&l.l1), ld(&l.t0), ld(&l.t1));
        let dot = |x: __m256d, y: __m256d, z: __m256d, u: __m256d, v: __m256d, w: __m256d| {
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, u), _mm256_mul_pd(y, v)), _mm256_mul_pd(z, w))
        };
        let m0 = dot(lx, ly, lz, c0x, c0y, c0z);
        let m1 = dot(lx, ly, lz, c1x, c1y, c1z);
        let r0 = _mm256_add_pd(dot(ax, ay, az, h0x, h0y, h0z), _mm256_mul_pd(m, l1));
        let r1 = dot(ax, ay, az, h1x, h1y, h1z);
        let f0a = _mm256_sub_pd(_mm256_sub_pd(m0, r0), t1);
        let f1a = _mm256_sub_pd(_mm256_sub_pd(_mm256_sub_pd(_mm256_add_pd(m0, m1), r0), r1), t1);
        let f0b = _mm256_sub_pd(_mm256_sub_pd(t0, m0), r0);
        let f1b = _mm256_sub_pd(_mm256_sub_pd(_mm256_sub_pd(_mm256_sub_pd(t0, m0), m1), r0), r1);
        for (a, b) in [(f0a, f1a), (f0b, f1b)] {
            let pa = _mm256_cmp_pd::<_CMP_GT_OQ>(a, zero);
            let pb = _mm256_cmp_pd::<_CMP_GT_OQ>(b, zero);
            reject = _mm256_or_pd(reject, _mm256_and_pd(pa, pb));
            let root = _mm256_div_pd(a, _mm256_sub_pd(a, b));
            // Masked-off lanes give 0 to the maximum and 1 to the minimum: neutral, as lo ≥ 0
            // and hi ≤ 1.
            lo = _mm256_max_pd(lo, _mm256_and_pd(pa, root));
            hi = _mm256_min_pd(hi, _mm256_blendv_pd(one, root, _mm256_andnot_pd(pa, pb)));
        }
    }
    if _mm256_movemask_pd(reject) != 0 {
        return false;
    }
    let mut los = [0.0f64; 4];
    let mut his = [0.0f64; 4];
    // SAFETY: four f64 each.
    unsafe {
        _mm256_storeu_pd(los.as_mut_ptr(), lo);
        _mm256_storeu_pd(his.as_mut_ptr(), hi);
    }
    los.iter().fold(0.0f64, |x, &y| x.max(y)) <= his.iter().fold(1.0f64, |x, &y| x.min(y))
}

/// The triangle clipped to the box [lo, hi] (Sutherland–Hodgman); empty if they do not meet.
#[cfg(test)]
pub fn clip_to_box(v: [DVec3; 3], lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    let (mut out, mut tmp) = (Vec::new(), Vec::new());
    clip_to_box_into(v, lo, hi, &mut out, &mut tmp);
    out
}

/// [`clip_to_box`] into `out`, with `tmp` as the second buffer (both reused, not allocated).
pub fn clip_to_box_into(v: [DVec3; 3], lo: DVec3, hi: DVec3, out: &mut Vec<DVec3>, tmp: &mut Vec<DVec3>) {
    out.clear();
    out.extend_from_slice(&v);
    for axis in 0..3 {
        for (bound, keep_below) in [(lo[axis], false), (hi[axis], true)] {
            if out.is_empty() {
                return;
            }
            let inside = |p: &DVec3| if keep_below { p[axis] <= bound } else { p[axis] >= bound };
            tmp.clear();
            for i in 0..out.len() {
                let (a, b) = (out[i], out[(i + 1) % out.len()]);
                let (ia, ib) = (inside(&a), inside(&b));
                if ia {
                    tmp.push(a);
                }
                if ia != ib {
                    let t = (bound - a[axis]) / (b[axis] - a[axis]);
                    let mut p = a + (b - a) * t;
                    p[axis] = bound;
                    tmp.push(p);
                }
            }
            std::mem::swap(out, tmp);
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Uniform numbers in [0, 1) from a 64-bit LCG seeded with `state` (the tests' own, so that
    /// their cases do not change with a crate's version).
    pub(crate) fn uniform(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Random sampling of hull points: any sampled point inside the triangle's slab-thin
    /// neighbourhood must be found by the exact test (it may find more: it is exact, sampling is not).
    #[test]
    fn sweep_test_agrees_with_dense_sampling() {
        let mut rnd = uniform(12345);
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

    /// The AVX2 sweep is an optimisation of the scalar one: same answer on every test, including
    /// boxes that only graze the triangle (found by bisecting each sweep's boundary).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_sweep_matches_the_scalar_one() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let mut rnd = uniform(99);
        let (mut met, mut missed) = (0, 0);
        for _ in 0..20_000 {
            let v = [0; 3].map(|_| DVec3::new(rnd(), rnd(), rnd()) * 1.4 - 0.2);
            let tri = Prepared::new(v);
            let c0 = DVec3::new(rnd(), rnd(), 0.0);
            let c1 = DVec3::new(rnd(), rnd(), 1.0) - c0;
            let h0 = DVec3::new(rnd(), rnd(), 0.0) * 0.3;
            let h1 = DVec3::new(rnd(), rnd(), 0.0) * 0.3 - h0;
            // Scale the boxes to the edge of touching: the bisection ends on the two sides of it.
            let (mut a, mut b) = (0.0f64, 1.0f64);
            for _ in 0..40 {
                let k = 0.5 * (a + b);
                if sweep(&tri.lanes, c0, c1, h0 * k, h1 * k, 1e-6) {
                    b = k;
                } else {
                    a = k;
                }
            }
            for k in [a, b, 1.0, 0.0] {
                let scalar = sweep(&tri.lanes, c0, c1, h0 * k, h1 * k, 1e-6);
                // SAFETY: AVX2 was detected above.
                let simd = unsafe { sweep_avx2(&tri.lanes, c0, c1, h0 * k, h1 * k, 1e-6) };
                assert_eq!(scalar, simd, "{v:?} {c0} {c1} {h0} {h1} {k}");
                if scalar { met += 1 } else { missed += 1 }
            }
        }
        assert!(met > 10_000 && missed > 10_000, "{met} met, {missed} missed");
    }

    /// The AVX2 many-shaft test and the portable one give the same masks (a compile on a CPU
    /// without AVX2 writes the same bytes).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_shaft_lanes_match_the_portable_ones() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let mut rnd = uniform(5);
        let mut nonzero = 0;
        for case in 0..20_000u32 {
            let n = 1 + case % 8;
            let c = DVec3::new(rnd(), rnd(), rnd());
            let size = [0.05, 0.5, 2.0][(case % 3) as usize];
            let tri = Prepared::new([0; 3].map(|_| c + (DVec3::new(rnd(), rnd(), rnd()) - 0.5) * size));
            let pair = case % 15;
            let (fa, fb) = kiln_format::linespace::index::pair_faces(pair);
            let axes = tri.pair_axes(fa, fb, n, [0.0, 1e-5, 1e-2][(case % 5 % 3) as usize]);
            let r = |k: f64| (k * n as f64) as u32;
            let (u0, v0) = (r(rnd()), r(rnd()));
            let rect = [u0, (u0 + 1 + r(rnd())).min(n), v0, (v0 + 1 + r(rnd())).min(n)];
            let (au, av) = (r(rnd()), r(rnd()));
            let portable = shafts(&axes, au, av, rect);
            // SAFETY: AVX2 was detected above.
            let simd = unsafe { shafts_avx2(&axes, au, av, rect) };
            assert_eq!(portable, simd, "case {case}");
            nonzero += (portable != 0) as u32;
        }
        assert!(nonzero > 2000, "{nonzero}");
    }

    /// The many-shaft test against the one-shaft sweep, shaft by shaft: random triangles (some
    /// leaving the cell), every face pair, random source patches and target rectangles, N = 1…8.
    #[test]
    fn shaft_lanes_agree_with_the_sweep() {
        use kiln_format::linespace::index::{FACE_PAIRS, pair_faces};
        let mut rnd = uniform(7);
        let (mut met, mut tested) = (0u64, 0u64);
        for case in 0..3000 {
            let n = 1 + case % 8;
            let size = if case % 3 == 0 { 0.2 } else { 1.2 };
            let c = DVec3::new(rnd(), rnd(), rnd());
            let v = [0; 3].map(|_| c + (DVec3::new(rnd(), rnd(), rnd()) - 0.5) * size);
            let tri = Prepared::new(v);
            let margin = if case % 2 == 0 { 0.0 } else { 1e-3 };
            for pair in 0..FACE_PAIRS {
                let (fa, fb) = pair_faces(pair);
                let (au, av) = ((rnd() * n as f64) as u32, (rnd() * n as f64) as u32);
                let u0 = (rnd() * n as f64) as u32;
                let v0 = (rnd() * n as f64) as u32;
                let rect = [
                    u0,
                    u0 + 1 + (rnd() * (n - u0) as f64) as u32,
                    v0,
                    v0 + 1 + (rnd() * (n - v0) as f64) as u32,
                ];
                let rect = [rect[0], rect[1].min(n), rect[2], rect[3].min(n)];
                // The face boxes, written out here: a face is the plane axis = 0 or 1.
                let face_box = |face: u32, iu: u32, iv: u32| {
                    let (x, (ua, va)) = (face_axis(face), face_uv_axes(face));
                    let s = 1.0 / n as f64;
                    let mut c = DVec3::ZERO;
                    let mut h = DVec3::ZERO;
                    c[x] = (face % 2) as f64;
                    c[ua] = (iu as f64 + 0.5) * s;
                    c[va] = (iv as f64 + 0.5) * s;
                    h[ua] = 0.5 * s;
                    h[va] = 0.5 * s;
                    (c, h)
                };
                let (ca, ha) = face_box(fa, au, av);
                let mask = tri.pair_axes(fa, fb, n, margin).shafts_from(au, av, rect);
                let w = rect[3] - rect[2];
                for u in rect[0]..rect[1] {
                    for vv in rect[2]..rect[3] {
                        let (cb, hb) = face_box(fb, u, vv);
                        let one = tri.overlaps_sweep(ca, cb - ca, ha, hb - ha, margin);
                        let bit = (u - rect[0]) * w + (vv - rect[2]);
                        assert_eq!(
                            mask >> bit & 1 == 1,
                            one,
                            "case {case} pair {pair} a ({au},{av}) b ({u},{vv}) {v:?}"
                        );
                        met += one as u64;
                        tested += 1;
                    }
                }
            }
        }
        assert!(met > tested / 10 && met < tested * 9 / 10, "{met} of {tested}");
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
