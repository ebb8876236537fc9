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

use super::simd::Simd;

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

    /// The triangle's separations from the patches of face `face` at resolution `n`, as either
    /// end of a shaft: [`PairAxes`] of two of them are the separations for the shafts of a face
    /// pair, ready for [`PairAxes::masks`] and [`PairAxes::shafts_among`].
    pub fn face_axes(&self, face: u32, n: u32, margin: f64) -> FaceAxes {
        let mut f = FaceAxes::default();
        self.face_axes_into(face, n, margin, &mut f);
        f
    }

    /// [`Self::face_axes`] into `f`.
    fn face_axes_into(&self, face: u32, n: u32, margin: f64, f: &mut FaceAxes) {
        let l = &self.lanes;
        let s = 1.0 / n as f64;
        let half = 0.5 * s;
        // A patch of face f at indices (u, v) is the box with centre (f mod 2) on f's axis and
        // (index + 1/2)·s on the other two, half extent s/2 on those. So on every axis the
        // centre's projection is affine in (u, v) and the box's radius is one number.
        let (j, plane) = (face_axis(face), (face % 2) as f64);
        let (ua, va) = face_uv_axes(face);
        for i in 0..LANES {
            let lv = [l.l[0][i], l.l[1][i], l.l[2][i]];
            let av = [l.a[0][i], l.a[1][i], l.a[2][i]];
            let k = lv[j] * plane + (lv[ua] + lv[va]) * half;
            let r = (av[ua] + av[va]) * half + margin * l.l1[i];
            // Positive: separated. Box minimum minus triangle maximum is k − r − t1 plus
            // (u·du + v·dv); triangle minimum minus box maximum is t0 − k − r minus it.
            f.sep[0][i] = k - r - l.t1[i];
            f.sep[1][i] = l.t0[i] - k - r;
            (f.du[i], f.dv[i]) = (lv[ua] * s, lv[va] * s);
            (f.du[LANES + i], f.dv[LANES + i]) = (-f.du[i], -f.dv[i]);
        }
    }
}

/// One triangle's separations from the patches of each of the six faces at one resolution,
/// with their sign masks ([`Prepared::face_tables`]). A face pair's ([`Self::pair`]) are two of
/// them: each separation depends on its face alone, so a triangle's six faces serve its 15
/// pairs (made for every pair, the same numbers were a sixth of an object cell's bake).
///
/// A pair's separations and masks are views of two faces' ([`Self::pair`]): copied into one
/// value per pair (1.5 KB), they were a twentieth of the teapot's 32³ object cells' bake.
#[derive(Debug, Clone)]
pub struct FaceTables {
    /// Face f's separations, as either end of a shaft.
    axes: [FaceAxes; 6],
    /// The sign masks of the pair (f, f).
    masks: [MaskTable; 6],
}

impl Default for FaceTables {
    fn default() -> Self {
        let axes = FaceAxes::default();
        let masks = MaskTable::empty(0);
        FaceTables {
            axes: std::array::from_fn(|_| axes.clone()),
            masks: std::array::from_fn(|_| masks.clone()),
        }
    }
}

impl Prepared {
    /// [`FaceTables`] at resolution `n` with the grid margin `margin`.
    pub fn face_tables(&self, n: u32, margin: f64) -> FaceTables {
        let mut t = FaceTables::default();
        self.face_tables_into(n, margin, &mut t);
        t
    }

    /// [`Self::face_tables`] into `t` (made in place: a cell's kept tables are not moved).
    pub fn face_tables_into(&self, n: u32, margin: f64, t: &mut FaceTables) {
        for f in 0..6 {
            self.face_axes_into(f as u32, n, margin, &mut t.axes[f]);
            let axes = &t.axes[f];
            t.masks[f] = PairAxes { a: axes, b: axes }.masks(n);
        }
    }
}

impl FaceTables {
    /// The separations and sign masks of face pair (`fa`, `fb`): those of
    /// [`Prepared::face_axes`] and [`PairAxes::masks`], as views of the two faces' tables.
    pub fn pair(&self, fa: u32, fb: u32) -> (PairAxes<'_>, PairMasks<'_>) {
        let axes = PairAxes { a: &self.axes[fa as usize], b: &self.axes[fb as usize] };
        (axes, MaskTable::pair(&self.masks[fa as usize], &self.masks[fb as usize]))
    }

    /// [`PairMasks::survivors`] of the pair (`fa`, `fb`) (`masks`, from [`Self::pair`]), the
    /// same sets: with AVX-512, a separation at a time over eight patches of face a per
    /// register (face a's patches where a separation is positive are its mask by separation),
    /// instead of a patch at a time over its separations.
    pub fn survivors(&self, fa: u32, masks: &PairMasks, out: &mut [u64; MAX_PATCHES]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F.
            unsafe { survivors_avx512(&self.masks[fa as usize].at_b, masks, out) };
            return;
        }
        masks.survivors(out);
    }
}

/// [`FaceTables::survivors`] in AVX-512: `columns[c]`, face a's patches where separation `c` is
/// positive.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn survivors_avx512(columns: &[u64; 2 * LANES], m: &PairMasks<'_>, out: &mut [u64; MAX_PATCHES]) {
    use std::arch::x86_64::*;
    let n2 = (m.n * m.n) as usize;
    let groups = n2.div_ceil(8);
    let mut rejected = [_mm512_setzero_si512(); MAX_PATCHES / 8];
    for c in bits(m.some_b as u64) {
        let b = _mm512_set1_epi64(m.at_b[c] as i64);
        for (g, r) in rejected.iter_mut().enumerate().take(groups) {
            *r = _mm512_mask_or_epi64(*r, (columns[c] >> (8 * g)) as u8, *r, b);
        }
    }
    let all = _mm512_set1_epi64(low_bits(n2) as i64);
    for (g, r) in rejected.iter().enumerate().take(groups) {
        // SAFETY: 8·g + 8 <= MAX_PATCHES, `out`'s length.
        unsafe { _mm512_storeu_si512(out.as_mut_ptr().add(8 * g).cast(), _mm512_andnot_si512(*r, all)) };
    }
    // (The patches past n² of the last register: none.)
    out[n2..8 * groups].fill(0);
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

/// One triangle's separations from the patches of two faces, a view of each face's
/// ([`Prepared::face_axes`]): face a's as the a end of the shafts, face b's as the b end.
#[derive(Debug, Clone, Copy)]
pub struct PairAxes<'f> {
    pub a: &'f FaceAxes,
    pub b: &'f FaceAxes,
}

/// One triangle's separations from the patches of one face ([`Prepared::face_axes`]): on each
/// lane and side, `sep[side] ± (u·du + v·dv)` for the patch (u, v) (+ for side 0).
#[derive(Debug, Clone)]
pub struct FaceAxes {
    sep: [[f64; LANES]; 2],
    /// By pair (side·16 + lane): side 0's, then side 1's negated (the b end's step takes its
    /// pair's without branching on the side; a branch there mispredicted at every change of
    /// side in a chain of bounds). The a end's sums use side 0's.
    du: [f64; 2 * LANES],
    dv: [f64; 2 * LANES],
}

impl Default for FaceAxes {
    fn default() -> Self {
        FaceAxes { sep: [[0.0; LANES]; 2], du: [0.0; 2 * LANES], dv: [0.0; 2 * LANES] }
    }
}

/// The lanes holding real axes (the rest are padding, never separating).
const AXES: usize = 13;

/// Patches per face at the largest shaft resolution.
pub const MAX_PATCHES: usize = (MAX_SHAFT_RES * MAX_SHAFT_RES) as usize;

/// The mask of the lowest `count` (≤ 64) bits: every patch of a face of `count` patches.
#[inline(always)]
pub fn low_bits(count: usize) -> u64 {
    if count == 64 { u64::MAX } else { (1u64 << count) - 1 }
}

/// Patch coordinates (u, v) of patch p = u·n + v in f64, per n: `PATCH_UV[n][0][p]` is u,
/// `PATCH_UV[n][1][p]` is v (zero beyond n²).
static PATCH_UV: std::sync::LazyLock<[[[f64; MAX_PATCHES]; 2]; MAX_SHAFT_RES as usize + 1]> =
    std::sync::LazyLock::new(|| {
        let mut t = [[[0.0; MAX_PATCHES]; 2]; MAX_SHAFT_RES as usize + 1];
        for (n, table) in t.iter_mut().enumerate().skip(1) {
            let [us, vs] = table;
            for (p, (u, v)) in us.iter_mut().zip(vs.iter_mut()).enumerate().take(n * n) {
                (*u, *v) = ((p / n) as f64, (p % n) as f64);
            }
        }
        t
    });

/// The set bits of `mask`, lowest first.
#[inline(always)]
pub fn set_bits(mut mask: u64) -> impl Iterator<Item = u32> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let k = mask.trailing_zeros();
            mask &= mask - 1;
            k
        })
    })
}

/// [`set_bits`] as indices.
#[inline(always)]
fn bits(mask: u64) -> impl Iterator<Item = usize> {
    set_bits(mask).map(|k| k as usize)
}

/// Where one triangle's separations from the patches of a face pair are positive. A separation
/// is named by the bit `side·16 + lane` ("pair" below), a patch (u, v) by the bit u·n + v. A shaft
/// whose two ends are both separated by one pair misses the triangle
/// ([`PairMasks::survivors`]); the rest need [`PairAxes::shafts_among`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairMasks<'m> {
    n: u32,
    /// Per patch of face a (the a end of its shafts): the pairs positive there.
    at_a: &'m [u32; MAX_PATCHES],
    /// Per pair: the patches of face b (the b end) where it is positive.
    at_b: &'m [u64; 2 * LANES],
    /// The pairs positive at some patch of face b.
    some_b: u32,
    /// The patches of face b where none is: the triangle meets their boxes.
    free_b: u64,
}

/// The sign masks [`PairAxes::masks`] makes, held: [`PairMasks`] are views of one or two.
#[derive(Debug, Clone, PartialEq)]
pub struct MaskTable {
    n: u32,
    at_a: [u32; MAX_PATCHES],
    at_b: [u64; 2 * LANES],
    some_b: u32,
    free_b: u64,
}

impl MaskTable {
    /// No separation positive anywhere, at resolution `n` (filled by [`PairAxes::masks`]).
    fn empty(n: u32) -> MaskTable {
        MaskTable { n, at_a: [0; MAX_PATCHES], at_b: [0; 2 * LANES], some_b: 0, free_b: 0 }
    }

    /// The masks of the pair whose a end's are `a`'s and b end's `b`'s.
    pub fn pair<'m>(a: &'m MaskTable, b: &'m MaskTable) -> PairMasks<'m> {
        PairMasks { n: a.n, at_a: &a.at_a, at_b: &b.at_b, some_b: b.some_b, free_b: b.free_b }
    }

    /// The masks as a view.
    pub fn view(&self) -> PairMasks<'_> {
        MaskTable::pair(self, self)
    }

    /// `some_b` and `free_b` from `at_b`.
    fn finish_b(&mut self, n2: usize) {
        let all = low_bits(n2);
        let mut any = 0u64;
        for (c, &m) in self.at_b.iter().enumerate() {
            self.some_b |= ((m != 0) as u32) << c;
            any |= m;
        }
        self.free_b = all & !any;
    }
}

impl PairMasks<'_> {
    /// For every patch of face a, the patches of face b that no single pair separates at both
    /// ends (a superset of the shafts the triangle meets).
    pub fn survivors(&self, out: &mut [u64; MAX_PATCHES]) {
        let n2 = (self.n * self.n) as usize;
        let all = low_bits(n2);
        for (pa, out) in out.iter_mut().enumerate().take(n2) {
            let mut rejected = 0u64;
            for c in bits((self.at_a[pa] & self.some_b) as u64) {
                rejected |= self.at_b[c];
            }
            *out = all & !rejected;
        }
    }
}

impl PairAxes<'_> {
    /// The sign masks of every separation at every patch of both faces (resolution `n`), with
    /// the arithmetic of [`PairAxes::shafts_among`] (the same signs, bit for bit).
    pub fn masks(&self, n: u32) -> MaskTable {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports the features the function is compiled for.
            return unsafe { masks_avx2(self, n) };
        }
        self.masks_portable(n)
    }

    /// [`PairAxes::masks`] without SIMD intrinsics.
    fn masks_portable(&self, n: u32) -> MaskTable {
        let n2 = (n * n) as usize;
        let [us, vs] = &PATCH_UV[n as usize];
        let mut m = MaskTable::empty(n);
        for p in 0..n2 {
            let sa = self.a_end(us[p], vs[p]);
            for (c, &x) in sa.iter().enumerate() {
                m.at_a[p] |= ((x > 0.0) as u32) << c;
            }
        }
        for i in 0..AXES {
            for p in 0..n2 {
                let t = us[p] * self.b.du[i] + vs[p] * self.b.dv[i];
                m.at_b[i] |= ((self.b.sep[0][i] + t > 0.0) as u64) << p;
                m.at_b[LANES + i] |= ((self.b.sep[1][i] - t > 0.0) as u64) << p;
            }
        }
        m.finish_b(n2);
        m
    }

    /// The a end's separations of patch (u, v) of face a, by pair (zero on padding lanes).
    #[inline(always)]
    fn a_end(&self, u: f64, v: f64) -> [f64; 2 * LANES] {
        let mut sa = [0.0f64; 2 * LANES];
        for i in 0..AXES {
            let ta = u * self.a.du[i] + v * self.a.dv[i];
            sa[i] = self.a.sep[0][i] + ta;
            sa[LANES + i] = self.a.sep[1][i] - ta;
        }
        sa
    }

    /// The shafts from patch `pa` of face a to the patches of face b in `among` that meet the
    /// triangle, as a mask of the same bits: the sweep test of [`Prepared::overlaps_sweep`],
    /// shaft by shaft. `among` must leave out the shafts a single pair rejects
    /// ([`PairMasks::survivors`]).
    ///
    /// A pair positive at the a end bounds the shaft's s from below (s ≥ a/(a − b)); one positive
    /// at the b end only, from above (s ≤ −a/(b − a)). Without bounds of both kinds the interval
    /// is not empty; with them the roots are compared as fractions, without dividing.
    pub fn shafts_among(&self, pa: u32, among: u64, masks: &PairMasks) -> u64 {
        self.shafts_among_with(pa, among, masks, Simd::detect())
    }

    /// [`PairAxes::shafts_among`] with the per-shaft test of `simd` (which the CPU must have).
    #[inline(always)]
    fn shafts_among_with(&self, pa: u32, among: u64, masks: &PairMasks, simd: Simd) -> u64 {
        let lower = masks.at_a[pa as usize];
        debug_assert!(
            bits(lower as u64).all(|c| masks.at_b[c] & among == 0),
            "shafts one separation rejects at both ends must be left out"
        );
        if among == 0 || lower == 0 {
            return among;
        }
        // Shafts ending at a patch whose box meets the triangle have no upper bound.
        let test = among & !masks.free_b;
        #[cfg(target_arch = "x86_64")]
        if simd == Simd::Avx512 {
            // SAFETY: the caller has checked that the CPU has AVX-512F and BMI2.
            return unsafe { self.shafts_among_avx512(pa, among, lower, test, masks) };
        }
        let mut upper = 0u32;
        for c in bits((masks.some_b & !lower) as u64) {
            upper |= ((masks.at_b[c] & test != 0) as u32) << c;
        }
        if upper == 0 {
            return among;
        }
        let n = masks.n;
        let [us, vs] = &PATCH_UV[n as usize];
        let sa = self.a_end(us[pa as usize], vs[pa as usize]);
        // The tested patches' coordinates, in patch order (the lanes past `count` up to a
        // multiple of eight: finite padding, the vector kernels' results there dropped).
        let (mut bu, mut bv) = ([0.0f64; PADDED], [0.0f64; PADDED]);
        let count = compress(test, us, vs, &mut bu, &mut bv);
        let met = match simd {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the caller has checked that the CPU has AVX2.
            Simd::Avx2 => unsafe { groups_avx2(self, &sa, lower, upper, count, &bu, &bv) },
            _ => groups(self, &sa, lower, upper, count, &bu, &bv),
        };
        among & !test | deposit(met, test)
    }

    /// The rest of [`PairAxes::shafts_among`] after its first shortcut (the pairs `lower`
    /// positive at the a end; the shafts to `test`), in AVX-512 throughout: the pairs bounding
    /// from above found eight at a time, the a end's separations sixteen at a time, the tested
    /// patches' coordinates compressed eight at a time (into buffers left unfilled beyond them,
    /// whose zeroing was a twentieth of a candidate bake) and the results deposited with BMI2.
    /// The same bits as the portable code.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,bmi2")]
    unsafe fn shafts_among_avx512(
        &self,
        pa: u32,
        among: u64,
        lower: u32,
        test: u64,
        masks: &PairMasks,
    ) -> u64 {
        use std::arch::x86_64::*;
        use std::mem::MaybeUninit;
        let t = _mm512_set1_epi64(test as i64);
        let mut upper = 0u32;
        for g in 0..4 {
            // SAFETY: 8·g + 8 <= 2·LANES, `at_b`'s length.
            let at_b = unsafe { _mm512_loadu_si512(masks.at_b.as_ptr().add(8 * g).cast()) };
            upper |= (_mm512_test_epi64_mask(at_b, t) as u32) << (8 * g);
        }
        upper &= masks.some_b & !lower;
        if upper == 0 {
            return among;
        }
        let [us, vs] = &PATCH_UV[masks.n as usize];
        // `a_end`'s arithmetic, every lane (the padding's never read: no pair there is
        // positive).
        let mut sa = [0.0f64; 2 * LANES];
        let (u, v) = (_mm512_set1_pd(us[pa as usize]), _mm512_set1_pd(vs[pa as usize]));
        for h in (0..LANES).step_by(8) {
            // SAFETY: h + 8 <= LANES, no longer than the arrays read; LANES + h + 8 <= 2·LANES, `sa`'s.
            unsafe {
                let ld = |x: &[f64]| _mm512_loadu_pd(x.as_ptr().add(h));
                let ta = _mm512_add_pd(_mm512_mul_pd(u, ld(&self.a.du)), _mm512_mul_pd(v, ld(&self.a.dv)));
                _mm512_storeu_pd(sa.as_mut_ptr().add(h), _mm512_add_pd(ld(&self.a.sep[0]), ta));
                _mm512_storeu_pd(sa.as_mut_ptr().add(LANES + h), _mm512_sub_pd(ld(&self.a.sep[1]), ta));
            }
        }
        let (mut bu, mut bv) =
            (MaybeUninit::<[f64; PADDED]>::uninit(), MaybeUninit::<[f64; PADDED]>::uninit());
        let (bu, bv) = (bu.as_mut_ptr().cast::<f64>(), bv.as_mut_ptr().cast::<f64>());
        // SAFETY: the buffers hold PADDED lanes; the kernel reads the first count rounded up
        // to eight, which `compress_avx512` writes.
        let met = unsafe {
            let count = compress_avx512(test, us, vs, bu, bv);
            groups_avx512(self, &sa, lower, upper, count, bu, bv)
        };
        among & !test | _pdep_u64(met, test)
    }

    /// The b end's separation of pair `c` as base + u·du + v·dv (negating du and dv gives the
    /// same bits as subtracting for side 1).
    #[inline(always)]
    fn b_end(&self, c: usize) -> (f64, f64, f64) {
        (self.b.sep[c / LANES][c % LANES], self.b.du[c], self.b.dv[c])
    }
}

/// Lanes of the tested patches' coordinates: every patch, and a vector's worth of padding.
const PADDED: usize = MAX_PATCHES + 8;

/// Writes the coordinates (`us`, `vs`) of the patches in `set` to the first lanes of `bu`, `bv`,
/// in patch order; returns their count.
#[inline(always)]
fn compress(
    set: u64,
    us: &[f64; MAX_PATCHES],
    vs: &[f64; MAX_PATCHES],
    bu: &mut [f64; PADDED],
    bv: &mut [f64; PADDED],
) -> usize {
    let mut count = 0;
    for p in bits(set) {
        (bu[count], bv[count]) = (us[p], vs[p]);
        count += 1;
    }
    count
}

/// [`compress`] in AVX-512, eight patches at a time (a compressed vector written at the count
/// so far), into buffers of [`PADDED`] lanes; the lanes from the count to the next multiple of
/// eight are zeroed, so that every lane a kernel reads is written.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn compress_avx512(
    set: u64,
    us: &[f64; MAX_PATCHES],
    vs: &[f64; MAX_PATCHES],
    bu: *mut f64,
    bv: *mut f64,
) -> usize {
    use std::arch::x86_64::*;
    let mut count = 0;
    for g in 0..(64 - set.leading_zeros() as usize).div_ceil(8) {
        let m = (set >> (8 * g)) as u8;
        // SAFETY: 8·g + 8 <= MAX_PATCHES, the tables' length; count <= 8·g, so count + 8 <=
        // PADDED, the buffers' (the caller's promise).
        unsafe {
            let (u, v) = (_mm512_loadu_pd(us.as_ptr().add(8 * g)), _mm512_loadu_pd(vs.as_ptr().add(8 * g)));
            _mm512_storeu_pd(bu.add(count), _mm512_maskz_compress_pd(m, u));
            _mm512_storeu_pd(bv.add(count), _mm512_maskz_compress_pd(m, v));
        }
        count += m.count_ones() as usize;
    }
    // SAFETY: count <= MAX_PATCHES, so count + 8 <= PADDED.
    unsafe {
        _mm512_storeu_pd(bu.add(count), _mm512_setzero_pd());
        _mm512_storeu_pd(bv.add(count), _mm512_setzero_pd());
    }
    count
}

/// The bits of `value`, lowest first, placed at the set bits of `mask`, lowest first (bit k of
/// a kernel's result, for the k-th tested patch, at that patch's bit).
#[inline(always)]
fn deposit(mut value: u64, mask: u64) -> u64 {
    let mut out = 0;
    for p in set_bits(mask) {
        out |= (value & 1) << p;
        value >>= 1;
    }
    out
}

/// [`PairAxes::masks`] in AVX2, with the same arithmetic: face a four pairs at a time per
/// patch, face b four patches at a time per pair.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn masks_avx2(p: &PairAxes<'_>, n: u32) -> MaskTable {
    use std::arch::x86_64::*;
    let n2 = (n * n) as usize;
    let all = low_bits(n2);
    let [us, vs] = &PATCH_UV[n as usize];
    let zero = _mm256_setzero_pd();
    let gt = |x: __m256d| _mm256_cmp_pd::<_CMP_GT_OQ>(x, zero);
    let mut m = MaskTable::empty(n);
    // SAFETY (loads): g + 4 <= LANES, no longer than the arrays read.
    let ld = |x: &[f64], g: usize| unsafe { _mm256_loadu_pd(x.as_ptr().add(g)) };
    for (pa, at) in m.at_a.iter_mut().enumerate().take(n2) {
        let (u, v) = (_mm256_set1_pd(us[pa]), _mm256_set1_pd(vs[pa]));
        let mut bits = 0u32;
        for g in (0..LANES).step_by(4) {
            let ta = _mm256_add_pd(_mm256_mul_pd(u, ld(&p.a.du, g)), _mm256_mul_pd(v, ld(&p.a.dv, g)));
            let side0 = _mm256_movemask_pd(gt(_mm256_add_pd(ld(&p.a.sep[0], g), ta))) as u32;
            let side1 = _mm256_movemask_pd(gt(_mm256_sub_pd(ld(&p.a.sep[1], g), ta))) as u32;
            bits |= side0 << g | side1 << (LANES + g);
        }
        *at = bits;
    }
    for i in 0..AXES {
        let (b0, b1) = (_mm256_set1_pd(p.b.sep[0][i]), _mm256_set1_pd(p.b.sep[1][i]));
        let (du, dv) = (_mm256_set1_pd(p.b.du[i]), _mm256_set1_pd(p.b.dv[i]));
        let (mut m0, mut m1) = (0u64, 0u64);
        for g in (0..n2).step_by(4) {
            // SAFETY: g + 4 <= MAX_PATCHES, the tables' length (patches beyond n² are masked
            // off below).
            let (u, v) =
                unsafe { (_mm256_loadu_pd(us.as_ptr().add(g)), _mm256_loadu_pd(vs.as_ptr().add(g))) };
            let t = _mm256_add_pd(_mm256_mul_pd(u, du), _mm256_mul_pd(v, dv));
            m0 |= (_mm256_movemask_pd(gt(_mm256_add_pd(b0, t))) as u64) << g;
            m1 |= (_mm256_movemask_pd(gt(_mm256_sub_pd(b1, t))) as u64) << g;
        }
        m.at_b[i] = m0 & all;
        m.at_b[LANES + i] = m1 & all;
    }
    m.finish_b(n2);
    m
}

/// The per-shaft part of [`PairAxes::shafts_among`]: the pairs `lower` bound s from below, the
/// pairs `upper` from above (`sa`: their a ends), shaft `k` < `count` ends at the b patch
/// (`us[k]`, `vs[k]`); bit k of the result is set where that shaft meets the triangle. Plain
/// arithmetic (no fused multiply-adds), so that [`groups_avx2`] and [`groups_avx512`] give the
/// same bits.
fn groups(
    p: &PairAxes,
    sa: &[f64; 2 * LANES],
    lower: u32,
    upper: u32,
    count: usize,
    us: &[f64; PADDED],
    vs: &[f64; PADDED],
) -> u64 {
    let mut mask = 0u64;
    for k in 0..count {
        let (bu, bv) = (us[k], vs[k]);
        // Roots as fractions num/den (den > 0): the interval [lo, hi] of s the shaft leaves.
        let (mut lo_n, mut lo_d, mut hi_n, mut hi_d) = (0.0f64, 1.0f64, 1.0f64, 1.0f64);
        for c in bits(lower as u64) {
            let (a, (base, du, dv)) = (sa[c], p.b_end(c));
            // Separated at the a end: s ≥ a/(a − b) (b ≤ 0: the shafts with b > 0 are left
            // out by the caller).
            let b = base + (bu * du + bv * dv);
            let (num, den) = (a, a - b);
            if num * lo_d > lo_n * den {
                (lo_n, lo_d) = (num, den);
            }
        }
        for c in bits(upper as u64) {
            let (a, (base, du, dv)) = (sa[c], p.b_end(c));
            // Separated at the b end only: s ≤ a/(a − b) = −a/(b − a).
            let b = base + (bu * du + bv * dv);
            let (num, den) = (-a, b - a);
            if b > 0.0 && num * hi_d < hi_n * den {
                (hi_n, hi_d) = (num, den);
            }
        }
        mask |= ((lo_n * hi_d <= hi_n * lo_d) as u64) << k;
    }
    mask
}

/// Takes the lowest pair off `set`; returns its a end (`sa`) and its b end as
/// [`PairAxes::b_end`] gives it (the vector kernels' bound steps).
#[inline(always)]
fn pop_pair(set: &mut u32, sa: &[f64; 2 * LANES], p: &PairAxes) -> (f64, (f64, f64, f64)) {
    let c = set.trailing_zeros() as usize;
    *set &= *set - 1;
    (sa[c], p.b_end(c))
}

/// [`groups`] in AVX2 intrinsics, four shafts at a time, with the same arithmetic operation
/// for operation (the same bits).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn groups_avx2(
    p: &PairAxes,
    sa: &[f64; 2 * LANES],
    lower: u32,
    upper: u32,
    count: usize,
    us: &[f64; PADDED],
    vs: &[f64; PADDED],
) -> u64 {
    let mut mask = 0u64;
    let groups = count.div_ceil(4);
    let mut g = 0;
    while g + 1 < groups {
        // SAFETY: the caller's CPU has AVX2.
        mask |= unsafe { group_avx2::<2>(p, sa, lower, upper, g, us, vs) } << (4 * g);
        g += 2;
    }
    if g < groups {
        // SAFETY: as above.
        mask |= unsafe { group_avx2::<1>(p, sa, lower, upper, g, us, vs) } << (4 * g);
    }
    mask
}

/// `G` groups of four shafts of [`groups_avx2`] from group `first` on, side by side: each
/// interval's bound is a chain of compare-and-blend steps (latency, not throughput, bound), so
/// the groups' lower and upper bounds run as 2·`G` independent chains, interleaved.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn group_avx2<const G: usize>(
    p: &PairAxes,
    sa: &[f64; 2 * LANES],
    lower: u32,
    upper: u32,
    first: usize,
    us: &[f64; PADDED],
    vs: &[f64; PADDED],
) -> u64 {
    use std::arch::x86_64::*;
    let s = |x: f64| _mm256_set1_pd(x);
    let (zero, one) = (_mm256_setzero_pd(), s(1.0));
    let gt = |x: __m256d, y: __m256d| _mm256_cmp_pd::<_CMP_GT_OQ>(x, y);
    // SAFETY (loads): 4·(first + G) <= 4·ceil(count / 4) <= MAX_PATCHES < PADDED, the arrays'
    // length (the caller's groups cover the count, the lanes past it zeros).
    let bu: [__m256d; G] =
        std::array::from_fn(|k| unsafe { _mm256_loadu_pd(us.as_ptr().add(4 * (first + k))) });
    let bv: [__m256d; G] =
        std::array::from_fn(|k| unsafe { _mm256_loadu_pd(vs.as_ptr().add(4 * (first + k))) });
    let (mut lo_n, mut lo_d, mut hi_n, mut hi_d) = ([zero; G], [one; G], [one; G], [one; G]);
    let (mut lower, mut upper) = (lower, upper);
    while lower | upper != 0 {
        if lower != 0 {
            let (a, (base, du, dv)) = pop_pair(&mut lower, sa, p);
            let (num, base, du, dv) = (s(a), s(base), s(du), s(dv));
            for k in 0..G {
                let b =
                    _mm256_add_pd(base, _mm256_add_pd(_mm256_mul_pd(bu[k], du), _mm256_mul_pd(bv[k], dv)));
                let den = _mm256_sub_pd(num, b);
                let later = gt(_mm256_mul_pd(num, lo_d[k]), _mm256_mul_pd(lo_n[k], den));
                lo_n[k] = _mm256_blendv_pd(lo_n[k], num, later);
                lo_d[k] = _mm256_blendv_pd(lo_d[k], den, later);
            }
        }
        if upper != 0 {
            let (a, (base, du, dv)) = pop_pair(&mut upper, sa, p);
            let (va, num, base, du, dv) = (s(a), s(-a), s(base), s(du), s(dv));
            for k in 0..G {
                let b =
                    _mm256_add_pd(base, _mm256_add_pd(_mm256_mul_pd(bu[k], du), _mm256_mul_pd(bv[k], dv)));
                let den = _mm256_sub_pd(b, va);
                let earlier = _mm256_and_pd(
                    gt(b, zero),
                    _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_mul_pd(num, hi_d[k]), _mm256_mul_pd(hi_n[k], den)),
                );
                hi_n[k] = _mm256_blendv_pd(hi_n[k], num, earlier);
                hi_d[k] = _mm256_blendv_pd(hi_d[k], den, earlier);
            }
        }
    }
    let mut mask = 0u64;
    for k in 0..G {
        let ok =
            _mm256_cmp_pd::<_CMP_LE_OQ>(_mm256_mul_pd(lo_n[k], hi_d[k]), _mm256_mul_pd(hi_n[k], lo_d[k]));
        mask |= (_mm256_movemask_pd(ok) as u64) << (4 * k);
    }
    mask
}

/// [`groups`] in AVX-512, eight shafts at a time, with the same arithmetic operation for
/// operation (the same bits); up to four groups of eight side by side, their bounds'
/// compare-and-select chains interleaved (see [`group_avx2`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn groups_avx512(
    p: &PairAxes,
    sa: &[f64; 2 * LANES],
    lower: u32,
    upper: u32,
    count: usize,
    us: *const f64,
    vs: *const f64,
) -> u64 {
    let mut mask = 0u64;
    let groups = count.div_ceil(8);
    let mut g = 0;
    while g < groups {
        // SAFETY: the caller's CPU has AVX-512F; the groups are within the padded count.
        let (met, taken) = unsafe {
            match groups - g {
                1 => (group_avx512::<1>(p, sa, lower, upper, g, us, vs), 1),
                2 => (group_avx512::<2>(p, sa, lower, upper, g, us, vs), 2),
                3 => (group_avx512::<3>(p, sa, lower, upper, g, us, vs), 3),
                _ => (group_avx512::<4>(p, sa, lower, upper, g, us, vs), 4),
            }
        };
        mask |= met << (8 * g);
        g += taken;
    }
    mask
}

/// `G` groups of eight shafts of [`groups_avx512`] from group `first` on.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline]
unsafe fn group_avx512<const G: usize>(
    p: &PairAxes,
    sa: &[f64; 2 * LANES],
    lower: u32,
    upper: u32,
    first: usize,
    us: *const f64,
    vs: *const f64,
) -> u64 {
    use std::arch::x86_64::*;
    let s = |x: f64| _mm512_set1_pd(x);
    let (zero, one) = (_mm512_setzero_pd(), s(1.0));
    let (mul, add, sub) = (_mm512_mul_pd, _mm512_add_pd, _mm512_sub_pd);
    // SAFETY (loads): the groups lie within the lanes the caller wrote.
    let bu: [__m512d; G] = std::array::from_fn(|k| unsafe { _mm512_loadu_pd(us.add(8 * (first + k))) });
    let bv: [__m512d; G] = std::array::from_fn(|k| unsafe { _mm512_loadu_pd(vs.add(8 * (first + k))) });
    let (mut lo_n, mut lo_d, mut hi_n, mut hi_d) = ([zero; G], [one; G], [one; G], [one; G]);
    let (mut lower, mut upper) = (lower, upper);
    while lower | upper != 0 {
        if lower != 0 {
            let (a, (base, du, dv)) = pop_pair(&mut lower, sa, p);
            let (num, base, du, dv) = (s(a), s(base), s(du), s(dv));
            for k in 0..G {
                let b = add(base, add(mul(bu[k], du), mul(bv[k], dv)));
                let den = sub(num, b);
                let later = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(mul(num, lo_d[k]), mul(lo_n[k], den));
                lo_n[k] = _mm512_mask_mov_pd(lo_n[k], later, num);
                lo_d[k] = _mm512_mask_mov_pd(lo_d[k], later, den);
            }
        }
        if upper != 0 {
            let (a, (base, du, dv)) = pop_pair(&mut upper, sa, p);
            let (va, num, base, du, dv) = (s(a), s(-a), s(base), s(du), s(dv));
            for k in 0..G {
                let b = add(base, add(mul(bu[k], du), mul(bv[k], dv)));
                let den = sub(b, va);
                let positive = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(b, zero);
                let earlier =
                    _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(positive, mul(num, hi_d[k]), mul(hi_n[k], den));
                hi_n[k] = _mm512_mask_mov_pd(hi_n[k], earlier, num);
                hi_d[k] = _mm512_mask_mov_pd(hi_d[k], earlier, den);
            }
        }
    }
    let mut mask = 0u64;
    for k in 0..G {
        let ok = _mm512_cmp_pd_mask::<_CMP_LE_OQ>(mul(lo_n[k], hi_d[k]), mul(hi_n[k], lo_d[k]));
        mask |= (ok as u64) << (8 * k);
    }
    mask
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

    /// The AVX2 masks and the AVX2 and AVX-512 per-shaft tests give the portable ones' bits (a
    /// compile on a CPU without them writes the same bytes).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn vector_shaft_lanes_match_the_portable_ones() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let mut rnd = uniform(5);
        let (mut met, mut open) = (0u64, 0u64);
        for case in 0..6000u32 {
            let n = 1 + case % 8;
            let c = DVec3::new(rnd(), rnd(), rnd());
            let size = [0.05, 0.5, 2.0][(case % 3) as usize];
            let tri = Prepared::new([0; 3].map(|_| c + (DVec3::new(rnd(), rnd(), rnd()) - 0.5) * size));
            let pair = case % 15;
            let (fa, fb) = kiln_format::linespace::index::pair_faces(pair);
            let margin = [0.0, 1e-5, 1e-2][(case % 5 % 3) as usize];
            let (a, b) = (tri.face_axes(fa, n, margin), tri.face_axes(fb, n, margin));
            let axes = PairAxes { a: &a, b: &b };
            let table = axes.masks_portable(n);
            // SAFETY: AVX2 was detected above.
            assert_eq!(table, unsafe { masks_avx2(&axes, n) }, "case {case}");
            let masks = table.view();
            let mut among = [0u64; MAX_PATCHES];
            masks.survivors(&mut among);
            for pa in 0..n * n {
                let portable = axes.shafts_among_with(pa, among[pa as usize], &masks, Simd::None);
                for &kind in Simd::available() {
                    let simd = axes.shafts_among_with(pa, among[pa as usize], &masks, kind);
                    assert_eq!(portable, simd, "case {case} patch {pa} {kind:?}");
                }
                met += portable.count_ones() as u64;
                open += among[pa as usize].count_ones() as u64;
            }
        }
        assert!(met > 20_000 && met < open, "{met} of {open}");
    }

    /// A triangle's face tables give every pair's separations, masks and survivors as the
    /// pair's own computation does: random triangles (some spanning, some outside the cell),
    /// every pair, N = 1…8.
    #[test]
    fn face_tables_match_the_pairs() {
        use kiln_format::linespace::index::{FACE_PAIRS, pair_faces};
        let mut rnd = uniform(23);
        for case in 0..600 {
            let n = 1 + case % 8;
            let size = [0.05, 0.5, 3.0][case as usize % 3];
            let c = DVec3::new(rnd(), rnd(), rnd()) * 1.4 - 0.2;
            let v = [0; 3].map(|_| c + (DVec3::new(rnd(), rnd(), rnd()) - 0.5) * size);
            let tri = Prepared::new(v);
            let margin = [0.0, 1e-5, 1e-3][case as usize % 3];
            let tables = tri.face_tables(n, margin);
            for pair in 0..FACE_PAIRS {
                let (fa, fb) = pair_faces(pair);
                let (axes, masks) = tables.pair(fa, fb);
                let (a, b) = (tri.face_axes(fa, n, margin), tri.face_axes(fb, n, margin));
                let own_axes = PairAxes { a: &a, b: &b };
                let own_table = own_axes.masks(n);
                let own = own_table.view();
                assert_eq!(masks, own, "case {case} pair {pair}");
                let bits = |x: &FaceAxes| {
                    (x.sep.map(|l| l.map(f64::to_bits)), [x.du, x.dv].map(|l| l.map(f64::to_bits)))
                };
                assert_eq!((bits(axes.a), bits(axes.b)), (bits(own_axes.a), bits(own_axes.b)));
                let (mut fast, mut slow) = ([0u64; MAX_PATCHES], [7u64; MAX_PATCHES]);
                tables.survivors(fa, &masks, &mut fast);
                own.survivors(&mut slow);
                let n2 = (n * n) as usize;
                assert_eq!(fast[..n2], slow[..n2], "case {case} pair {pair}");
            }
        }
    }

    /// The masks and the per-shaft test against the one-shaft sweep, shaft by shaft: random
    /// triangles (some leaving the cell), every face pair, random source patches, every target
    /// patch, N = 1…8.
    #[test]
    fn shaft_lanes_agree_with_the_sweep() {
        use kiln_format::linespace::index::{FACE_PAIRS, pair_faces};
        let mut rnd = uniform(7);
        let (mut met, mut tested) = (0u64, 0u64);
        for case in 0..2000 {
            let n = 1 + case % 8;
            let size = if case % 3 == 0 { 0.2 } else { 1.2 };
            let c = DVec3::new(rnd(), rnd(), rnd());
            let v = [0; 3].map(|_| c + (DVec3::new(rnd(), rnd(), rnd()) - 0.5) * size);
            let tri = Prepared::new(v);
            let margin = if case % 2 == 0 { 0.0 } else { 1e-3 };
            for pair in 0..FACE_PAIRS {
                let (fa, fb) = pair_faces(pair);
                let (au, av) = ((rnd() * n as f64) as u32, (rnd() * n as f64) as u32);
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
                let (a, b) = (tri.face_axes(fa, n, margin), tri.face_axes(fb, n, margin));
                let axes = PairAxes { a: &a, b: &b };
                let table = axes.masks(n);
                let masks = table.view();
                let mut among = [0u64; MAX_PATCHES];
                masks.survivors(&mut among);
                let pa = au * n + av;
                let mask = axes.shafts_among(pa, among[pa as usize], &masks);
                for u in 0..n {
                    for vv in 0..n {
                        let (cb, hb) = face_box(fb, u, vv);
                        let one = tri.overlaps_sweep(ca, cb - ca, ha, hb - ha, margin);
                        assert_eq!(
                            mask >> (u * n + vv) & 1 == 1,
                            one,
                            "case {case} pair {pair} a ({au},{av}) b ({u},{vv}) {v:?}"
                        );
                        met += one as u64;
                        tested += 1;
                    }
                }
            }
        }
        assert!(met > tested / 20 && met < tested * 9 / 10, "{met} of {tested}");
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
