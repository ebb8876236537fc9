//! Midpoint segments against a triangle: the PNMT records' hits (single precision, the nearest
//! hit, not a watertight one), one segment at a time or all the segments from one patch to the
//! patches of a face at once (AVX2, the same arithmetic).

use glam::Vec3;

use super::geometry::{MAX_PATCHES, set_bits};
use super::simd::Simd;

/// A segment–triangle test for midpoint segments (PNMT records need the nearest hit, not a
/// watertight one): plane crossing, then three edge functions.
#[derive(Debug, Clone, Copy)]
pub(super) struct SegmentTest {
    pub(super) c: [Vec3; 3],
    n: Vec3,
    n2: f32,
    /// n × (each edge), corner to next corner: an edge function n · (edge × (p − corner)) is
    /// (n × edge) · (p − corner), one dot product per edge and hit instead of a cross product
    /// and a dot.
    m: [Vec3; 3],
}

impl SegmentTest {
    pub(super) fn new(c: [Vec3; 3]) -> SegmentTest {
        let n = (c[1] - c[0]).cross(c[2] - c[0]);
        let m = [n.cross(c[1] - c[0]), n.cross(c[2] - c[1]), n.cross(c[0] - c[2])];
        SegmentTest { c, n, n2: n.length_squared(), m }
    }

    /// (t, u, v) where the segment o → e crosses the triangle, if the crossing's segment
    /// parameter t passes `wanted` (checked before the
    /// edge functions: in cells of many triangles most crossings lie between a segment's
    /// nearest hits found already).
    #[inline(always)]
    pub(super) fn hit_if(&self, o: Vec3, e: Vec3, wanted: impl Fn(f32) -> bool) -> Option<Intersection> {
        let (t, w0, w2) = self.crossing(o, e, wanted)?;
        Some(Intersection { t, u: w2 / self.n2, v: w0 / self.n2 })
    }

    /// [`Self::hit_if`]'s t and the edge functions that make its barycentrics (v·n², u·n²).
    #[inline(always)]
    fn crossing(&self, o: Vec3, e: Vec3, wanted: impl Fn(f32) -> bool) -> Option<(f32, f32, f32)> {
        let d = e - o;
        let denom = self.n.dot(d);
        if denom == 0.0 || self.n2 == 0.0 {
            return None;
        }
        let t = self.n.dot(self.c[0] - o) / denom;
        if !(0.0..=1.0).contains(&t) || !wanted(t) {
            return None;
        }
        let p = o + d * t;
        let [a, b, c] = self.c;
        let w0 = self.m[0].dot(p - a);
        let w1 = self.m[1].dot(p - b);
        let w2 = self.m[2].dot(p - c);
        (w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0).then_some((t, w0, w2))
    }
}

/// Where a midpoint segment crosses a triangle.
#[derive(Debug, Clone, Copy)]
pub(super) struct Intersection {
    pub(super) t: f32,
    pub(super) u: f32,
    pub(super) v: f32,
}

/// The patch centres of one face, by coordinate (padded with zeros to [`MAX_PATCHES`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct FaceCentres {
    x: [f32; MAX_PATCHES],
    y: [f32; MAX_PATCHES],
    z: [f32; MAX_PATCHES],
}

impl FaceCentres {
    /// A face of centres at the origin (a placeholder where no segment is tested).
    pub(super) const ZERO: FaceCentres =
        FaceCentres { x: [0.0; MAX_PATCHES], y: [0.0; MAX_PATCHES], z: [0.0; MAX_PATCHES] };

    pub(super) fn new(centres: &[Vec3; MAX_PATCHES]) -> FaceCentres {
        FaceCentres { x: centres.map(|c| c.x), y: centres.map(|c| c.y), z: centres.map(|c| c.z) }
    }

    fn at(&self, p: usize) -> Vec3 {
        Vec3::new(self.x[p], self.y[p], self.z[p])
    }
}

/// Per patch of the far face, what [`SegmentTest::hits_among`] found: the crossing's t and the
/// edge functions that make its barycentrics.
#[derive(Debug, Clone, Copy)]
pub(super) struct LaneHits {
    t: [f32; MAX_PATCHES],
    w0: [f32; MAX_PATCHES],
    w2: [f32; MAX_PATCHES],
}

impl Default for LaneHits {
    fn default() -> Self {
        LaneHits { t: [0.0; MAX_PATCHES], w0: [0.0; MAX_PATCHES], w2: [0.0; MAX_PATCHES] }
    }
}

impl SegmentTest {
    /// The segments from `o` to the patches `among` (bit p for patch p) of the face `to` that
    /// cross the triangle at a t with `!(t >= front[p]) || !(t <= back[p])` (nearer either end
    /// than the segment's hits so far; NaN: none yet), as a mask of the same bits; each one's
    /// crossing is then [`Self::lane`]. The same hits, bit for bit, as [`Self::hit_if`] segment by
    /// segment. `front` and `back` hold at least the highest patch of `among` rounded up to a
    /// multiple of 16.
    pub(super) fn hits_among(
        &self,
        o: Vec3,
        to: &FaceCentres,
        among: u64,
        front: &[f32],
        back: &[f32],
        out: &mut LaneHits,
    ) -> u64 {
        self.hits_among_with(o, to, among, front, back, out, Simd::detect())
    }

    /// [`Self::hits_among`] with the instructions `simd` (the caller has checked that the CPU
    /// has them).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn hits_among_with(
        &self,
        o: Vec3,
        to: &FaceCentres,
        among: u64,
        front: &[f32],
        back: &[f32],
        out: &mut LaneHits,
        simd: Simd,
    ) -> u64 {
        if among == 0 || self.n2 == 0.0 {
            return 0;
        }
        let width = if simd == Simd::Avx512 { 16 } else { 8 };
        let lanes = (64 - among.leading_zeros() as usize).next_multiple_of(width);
        assert!(front.len() >= lanes && back.len() >= lanes, "the ends' t cover the lanes");
        #[cfg(target_arch = "x86_64")]
        match simd {
            // SAFETY: the CPU has AVX-512F; the lanes are within `front`, `back` (asserted) and
            // the MAX_PATCHES arrays (a multiple of 16).
            Simd::Avx512 => return unsafe { self.hits_avx512(o, to, among, lanes, front, back, out) },
            // SAFETY: as above, with AVX2 and 8.
            Simd::Avx2 => return unsafe { self.hits_avx2(o, to, among, lanes, front, back, out) },
            Simd::None => {}
        }
        let mut hits = 0;
        for p in set_bits(among) {
            let p = p as usize;
            let wanted = |t: f32| !(t >= front[p]) || !(t <= back[p]);
            if let Some((t, w0, w2)) = self.crossing(o, to.at(p), wanted) {
                hits |= 1 << p;
                (out.t[p], out.w0[p], out.w2[p]) = (t, w0, w2);
            }
        }
        hits
    }

    /// The crossing [`Self::hits_among`] found towards patch `p`.
    #[inline(always)]
    pub(super) fn lane(&self, hits: &LaneHits, p: u32) -> Intersection {
        let p = p as usize;
        Intersection { t: hits.t[p], u: hits.w2[p] / self.n2, v: hits.w0[p] / self.n2 }
    }

    /// The crossings of the patches `p` as [`Self::lane`]'s numerators and denominator:
    /// (u numerators, v numerators, denominator), u = w2 / n2 and v = w0 / n2 in each lane.
    pub(super) fn lanes_x8(&self, hits: &LaneHits, p: &[u32; 8]) -> ([f32; 8], [f32; 8], f32) {
        (p.map(|p| hits.w2[p as usize]), p.map(|p| hits.w0[p as usize]), self.n2)
    }

    /// [`Self::hits_among`] in AVX-512, sixteen segments at a time, with [`Self::hit_if`]'s
    /// operations in its order (no fused multiply-adds).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn hits_avx512(
        &self,
        o: Vec3,
        to: &FaceCentres,
        among: u64,
        lanes: usize,
        front: &[f32],
        back: &[f32],
        out: &mut LaneHits,
    ) -> u64 {
        use std::arch::x86_64::*;
        let s = _mm512_set1_ps;
        let dot = |a: Vec3, x: __m512, y: __m512, z: __m512| {
            _mm512_add_ps(
                _mm512_add_ps(_mm512_mul_ps(s(a.x), x), _mm512_mul_ps(s(a.y), y)),
                _mm512_mul_ps(s(a.z), z),
            )
        };
        let num = s(self.n.dot(self.c[0] - o));
        let (zero, one) = (_mm512_setzero_ps(), s(1.0));
        let mut hits = 0u64;
        for g in (0..lanes).step_by(16) {
            let group = (among >> g) as u16;
            if group == 0 {
                continue;
            }
            // SAFETY (loads, stores): g + 16 <= lanes <= MAX_PATCHES and <= front, back's
            // lengths (the caller's contract).
            let ld = |a: &[f32]| unsafe { _mm512_loadu_ps(a.as_ptr().add(g)) };
            let dx = _mm512_sub_ps(ld(&to.x), s(o.x));
            let dy = _mm512_sub_ps(ld(&to.y), s(o.y));
            let dz = _mm512_sub_ps(ld(&to.z), s(o.z));
            let denom = dot(self.n, dx, dy, dz);
            let t = _mm512_div_ps(num, denom);
            let crossing = _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(denom, zero)
                & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(t, zero)
                & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(t, one);
            let wanted = _mm512_cmp_ps_mask::<_CMP_NGE_UQ>(t, ld(front))
                | _mm512_cmp_ps_mask::<_CMP_NLE_UQ>(t, ld(back));
            let live = crossing & wanted & group;
            if live == 0 {
                continue;
            }
            let px = _mm512_add_ps(s(o.x), _mm512_mul_ps(dx, t));
            let py = _mm512_add_ps(s(o.y), _mm512_mul_ps(dy, t));
            let pz = _mm512_add_ps(s(o.z), _mm512_mul_ps(dz, t));
            let edge = |m: Vec3, c: Vec3| {
                dot(m, _mm512_sub_ps(px, s(c.x)), _mm512_sub_ps(py, s(c.y)), _mm512_sub_ps(pz, s(c.z)))
            };
            let [a, b, c] = self.c;
            let (w0, w1, w2) = (edge(self.m[0], a), edge(self.m[1], b), edge(self.m[2], c));
            let found = live
                & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(w0, zero)
                & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(w1, zero)
                & _mm512_cmp_ps_mask::<_CMP_GE_OQ>(w2, zero);
            if found != 0 {
                // SAFETY: as the loads.
                unsafe {
                    _mm512_storeu_ps(out.t.as_mut_ptr().add(g), t);
                    _mm512_storeu_ps(out.w0.as_mut_ptr().add(g), w0);
                    _mm512_storeu_ps(out.w2.as_mut_ptr().add(g), w2);
                }
                hits |= (found as u64) << g;
            }
        }
        hits
    }

    /// [`Self::hits_among`] in AVX2, eight segments at a time, with [`Self::hit_if`]'s operations
    /// in its order (no fused multiply-adds).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn hits_avx2(
        &self,
        o: Vec3,
        to: &FaceCentres,
        among: u64,
        lanes: usize,
        front: &[f32],
        back: &[f32],
        out: &mut LaneHits,
    ) -> u64 {
        use std::arch::x86_64::*;
        let s = _mm256_set1_ps;
        let dot = |a: Vec3, x: __m256, y: __m256, z: __m256| {
            _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(s(a.x), x), _mm256_mul_ps(s(a.y), y)),
                _mm256_mul_ps(s(a.z), z),
            )
        };
        // The same for every segment from o: n · (c0 − o).
        let num = s(self.n.dot(self.c[0] - o));
        let (zero, one) = (_mm256_setzero_ps(), s(1.0));
        let mut hits = 0u64;
        for g in (0..lanes).step_by(8) {
            let group = (among >> g) as u32 & 0xff;
            if group == 0 {
                continue;
            }
            // SAFETY (loads, stores): g + 8 <= lanes <= MAX_PATCHES and <= front, back's
            // lengths (the caller's contract).
            let ld = |a: &[f32]| unsafe { _mm256_loadu_ps(a.as_ptr().add(g)) };
            let dx = _mm256_sub_ps(ld(&to.x), s(o.x));
            let dy = _mm256_sub_ps(ld(&to.y), s(o.y));
            let dz = _mm256_sub_ps(ld(&to.z), s(o.z));
            let denom = dot(self.n, dx, dy, dz);
            let t = _mm256_div_ps(num, denom);
            let crossing = _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_NEQ_UQ>(denom, zero),
                _mm256_and_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(t, zero), _mm256_cmp_ps::<_CMP_LE_OQ>(t, one)),
            );
            let wanted = _mm256_or_ps(
                _mm256_cmp_ps::<_CMP_NGE_UQ>(t, ld(front)),
                _mm256_cmp_ps::<_CMP_NLE_UQ>(t, ld(back)),
            );
            let live = _mm256_movemask_ps(_mm256_and_ps(crossing, wanted)) as u32 & group;
            if live == 0 {
                continue;
            }
            let px = _mm256_add_ps(s(o.x), _mm256_mul_ps(dx, t));
            let py = _mm256_add_ps(s(o.y), _mm256_mul_ps(dy, t));
            let pz = _mm256_add_ps(s(o.z), _mm256_mul_ps(dz, t));
            let edge = |m: Vec3, c: Vec3| {
                dot(m, _mm256_sub_ps(px, s(c.x)), _mm256_sub_ps(py, s(c.y)), _mm256_sub_ps(pz, s(c.z)))
            };
            let [a, b, c] = self.c;
            let (w0, w1, w2) = (edge(self.m[0], a), edge(self.m[1], b), edge(self.m[2], c));
            let inside = _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(w0, zero),
                _mm256_and_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(w1, zero), _mm256_cmp_ps::<_CMP_GE_OQ>(w2, zero)),
            );
            let found = _mm256_movemask_ps(inside) as u32 & live;
            if found != 0 {
                // SAFETY: as the loads.
                unsafe {
                    _mm256_storeu_ps(out.t.as_mut_ptr().add(g), t);
                    _mm256_storeu_ps(out.w0.as_mut_ptr().add(g), w0);
                    _mm256_storeu_ps(out.w2.as_mut_ptr().add(g), w2);
                }
                hits |= (found as u64) << g;
            }
        }
        hits
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::linespace::geometry::tests::uniform;

    /// The AVX2 and AVX-512 segment tests give the portable ones' hits, t and barycentrics bit for bit:
    /// random triangles (some degenerate, some in a face's plane, so that segments start or end
    /// on them: t = 0 or 1), random fronts and backs (some NaN: none yet), every lane count.
    #[test]
    fn vector_segments_match_the_portable_ones() {
        // This CPU's vector kinds (the first of `available` is the portable code itself).
        let kinds = &Simd::available()[1..];
        if kinds.is_empty() {
            return;
        }
        let mut rnd = uniform(7);
        let mut centres = [Vec3::ZERO; MAX_PATCHES];
        let (mut hits, mut lanes) = (0u32, 0u32);
        for case in 0..6000u32 {
            let n = 1 + case as usize % 8;
            // Face x = 1's patch centres, from patch (0.5, 0.5) of face x = 0.
            for (p, c) in centres.iter_mut().enumerate().take(n * n) {
                *c = Vec3::new(1.0, ((p / n) as f32 + 0.5) / n as f32, ((p % n) as f32 + 0.5) / n as f32);
            }
            let to = FaceCentres::new(&centres);
            let o = Vec3::new(0.0, rnd() as f32, rnd() as f32);
            let mut corner = || Vec3::new(rnd() as f32 * 1.4 - 0.2, rnd() as f32, rnd() as f32);
            let mut c = [corner(), corner(), corner()];
            match case % 5 {
                0 => c[2] = c[0] + (c[1] - c[0]) * 0.5,
                1 => c.iter_mut().for_each(|p| p.x = 1.0),
                2 => c.iter_mut().for_each(|p| p.x = 0.0),
                _ => {}
            }
            let seg = SegmentTest::new(c);
            let ends = |rnd: &mut dyn FnMut() -> f64| -> Vec<f32> {
                (0..MAX_PATCHES).map(|_| if rnd() < 0.3 { f32::NAN } else { rnd() as f32 }).collect()
            };
            let (front, back) = (ends(&mut rnd), ends(&mut rnd));
            let among = (rnd() * u64::MAX as f64) as u64 & crate::bake::linespace::geometry::low_bits(n * n);
            let mut b = LaneHits::default();
            let portable = seg.hits_among_with(o, &to, among, &front, &back, &mut b, Simd::None);
            for &kind in kinds {
                let mut a = LaneHits::default();
                let simd = seg.hits_among_with(o, &to, among, &front, &back, &mut a, kind);
                assert_eq!(simd, portable, "case {case} {kind:?}");
                for p in set_bits(simd) {
                    let (x, y) = (seg.lane(&a, p), seg.lane(&b, p));
                    let bits = |h: Intersection| [h.t.to_bits(), h.u.to_bits(), h.v.to_bits()];
                    assert_eq!(bits(x), bits(y), "case {case} patch {p} {kind:?}");
                    hits += 1;
                    lanes += (x.t == 0.0 || x.t == 1.0) as u32;
                }
            }
        }
        // Enough hits, some at a segment's ends, or the comparison says little.
        assert!(hits > 3000 && lanes > 100, "{hits} hits, {lanes} at an end");
    }
}
