//! PNMT records: position, normal, material and texture coordinates of the front or back hit
//! of a shaft's midpoint ray, in one of three layouts ([`PnmtLayout`], named by the grid
//! header):
//!
//! | layout | bytes | position | normal (octahedral, Meyer et al. 2010) | material | uv |
//! |---|---|---|---|---|---|
//! | full | 16 | u16 × 3 (cell / 65535) | snorm16 × 2 (< 0.005°) | u16 | f16 × 2 |
//! | compact | 12 | 10 bits × 3 (cell / 1023) | 11 bits × 2 (< 0.12°) | 12 bits | f16 × 2 |
//! | compact without uv | 8 | as compact | as compact | as compact | none |
//!
//! The full record's words (little-endian u32): position x | y << 16, position z | material <<
//! 16, normal x | y << 16, uv x | y << 16 (binary16 bits). The compact record's: position x | y
//! << 10 | z << 20 | material bits 10..12 << 30; normal x | y << 11 (each the snorm value plus
//! 1023) | material bits 0..10 << 22; then the uv word unless it is left out.
//!
//! Positions are relative to the voxel ([0, 1]³ mapped to the steps). The thesis stored 16 half
//! floats per shaft (32 bytes, world positions in half precision); kiln stores 16–32 bytes per
//! filled shaft (front and back). The compact layouts' quantisation (at most half a step,
//! 4.9e-4 cells, and 0.12°) is far below the record's own approximation: a midpoint ray stands
//! for every ray of a shaft up to a patch wide.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec2, Vec3};
use half::f16;

/// Material value of an absent record (full layout).
pub const NO_RECORD: u16 = 0xffff;

/// Material value of an absent record (compact layouts: 12 bits).
pub const NO_RECORD_COMPACT: u16 = 0xfff;

/// Words of the longest record: the encoders' output, of which a layout stores the first
/// [`PnmtLayout::words`].
pub type RecordWords = [u32; 4];

/// How a file stores its PNMT records ([`crate::linespace::GridHeader::pnmt_layout`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PnmtLayout {
    /// 16 bytes a record ([`PnmtRecord`]).
    #[default]
    Full,
    /// 12 bytes: coarser position and normal, materials below [`NO_RECORD_COMPACT`].
    Compact,
    /// 8 bytes: compact without texture coordinates (for scenes that sample no texture; they
    /// decode as zero).
    CompactNoUv,
}

impl PnmtLayout {
    /// Every layout with its header code and its name in settings.
    pub const ALL: [(PnmtLayout, u32, &'static str); 3] =
        [(Self::Full, 0, "full"), (Self::Compact, 1, "compact"), (Self::CompactNoUv, 2, "compact-no-uv")];

    /// The layout of a header code, `None` for an undefined one.
    pub fn from_code(code: u32) -> Option<PnmtLayout> {
        Self::ALL.iter().find(|l| l.1 == code).map(|l| l.0)
    }

    /// The header code.
    pub fn code(self) -> u32 {
        Self::ALL.iter().find(|l| l.0 == self).map_or(0, |l| l.1)
    }

    /// The name in settings and reports.
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|l| l.0 == self).map_or("full", |l| l.2)
    }

    /// 32-bit words a record.
    pub const fn words(self) -> usize {
        match self {
            Self::Full => 4,
            Self::Compact => 3,
            Self::CompactNoUv => 2,
        }
    }

    /// Whether records hold texture coordinates ([`Self::encode`] ignores them otherwise).
    pub const fn stores_uv(self) -> bool {
        !matches!(self, Self::CompactNoUv)
    }

    /// Quantisation steps of a position across a cell.
    pub const fn position_steps(self) -> f64 {
        match self {
            Self::Full => 65535.0,
            _ => 1023.0,
        }
    }

    /// The largest material index a record can hold.
    pub const fn max_material(self) -> u16 {
        match self {
            Self::Full => NO_RECORD - 1,
            _ => NO_RECORD_COMPACT - 1,
        }
    }

    /// The absent record.
    #[inline]
    pub fn none(self) -> RecordWords {
        match self {
            Self::Full => bytemuck::cast(PnmtRecord::NONE),
            _ => [(NO_RECORD_COMPACT as u32 >> 10) << 30, (NO_RECORD_COMPACT as u32 & 0x3ff) << 22, 0, 0],
        }
    }

    /// The material of a record (`words` at least [`Self::words`] long), [`NO_RECORD`] for an
    /// absent one.
    #[inline]
    pub fn material(self, w: &[u32]) -> u16 {
        match self {
            Self::Full => (w[1] >> 16) as u16,
            _ => {
                let m = (w[1] >> 22 | (w[0] >> 30) << 10) as u16;
                if m == NO_RECORD_COMPACT { NO_RECORD } else { m }
            }
        }
    }

    /// Whether a record holds a hit.
    #[inline]
    pub fn is_some(self, w: &[u32]) -> bool {
        self.material(w) != NO_RECORD
    }

    /// Encodes a hit in the voxel with minimum corner `cell_min` and edge `cell`; materials
    /// beyond [`Self::max_material`] are clamped to it. `normal` need not be of unit length (+Z
    /// where it is zero or not finite).
    pub fn encode(
        self,
        position: DVec3,
        normal: Vec3,
        material: u16,
        uv: Vec2,
        cell_min: DVec3,
        cell: f64,
    ) -> RecordWords {
        // One division, not three: they were a quarter of the encoding's time in the bake.
        let local = ((position - cell_min) * (1.0 / cell)).clamp(DVec3::ZERO, DVec3::ONE);
        let steps = self.position_steps();
        let q = local.to_array().map(|x| round_unsigned(x * steps));
        // The octahedral map divides by the L1 norm, so any finite non-zero direction will do,
        // unit or not (normalising it first was a tenth of the PNMT bake). A zero or non-finite
        // one maps to NaN, which the rounding below makes 0: +Z.
        let e = oct_encode(normal);
        let snorm = if self == Self::Full { 32767.0 } else { 1023.0 };
        let s = [e.x, e.y].map(|x| round_signed(x.clamp(-1.0, 1.0) * snorm));
        let m = material.min(self.max_material()) as u32;
        // Only for layouts that store it: baseline x86-64 has no F16C, so each conversion is a
        // software routine.
        let uv = || f16::from_f32(uv.x).to_bits() as u32 | (f16::from_f32(uv.y).to_bits() as u32) << 16;
        match self {
            Self::Full => {
                [q[0] | q[1] << 16, q[2] | m << 16, s[0] as u16 as u32 | (s[1] as u16 as u32) << 16, uv()]
            }
            // snorm11: −1023..=1023, stored plus 1023.
            _ => {
                let s = s.map(|x| (x + 1023) as u32);
                [
                    q[0] | q[1] << 10 | q[2] << 20 | (m >> 10) << 30,
                    s[0] | s[1] << 11 | (m & 0x3ff) << 22,
                    if self == Self::Compact { uv() } else { 0 },
                    0,
                ]
            }
        }
    }

    /// Eight hits' records in the compact layout without uv at once (AVX2): lane k's two words
    /// are those of `CompactNoUv.encode(positions[·][k] as f64, normals[·][k], materials[k], _,
    /// cell_min, cell)`, bit for bit, for each lane set in the returned mask: the lanes whose
    /// normal is finite and non-zero with a finite octahedral map (the rest need [`Self::encode`]).
    /// `None` where the CPU lacks AVX2. The bakes' walls write tens of millions of records, and
    /// encoding them one at a time was a quarter of a wall cell's bake.
    pub fn encode_compact_x8(
        positions: &[[f32; 8]; 3],
        normals: &[[f32; 8]; 3],
        materials: &[u16; 8],
        cell_min: DVec3,
        cell: f64,
    ) -> Option<([[u32; 2]; 8], u8)> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let m = materials.map(|m| m.min(Self::CompactNoUv.max_material()) as u32);
            // SAFETY: the CPU has AVX2.
            return Some(unsafe { compact_x8(positions, normals, &m, cell_min, cell) });
        }
        let _ = (positions, normals, materials, cell_min, cell);
        None
    }

    /// Decodes a record (`words` at least [`Self::words`] long) of the voxel with minimum
    /// corner `cell_min` and edge `cell`.
    pub fn decode(self, w: &[u32], cell_min: DVec3, cell: f64) -> Option<PnmtHit> {
        match self {
            Self::Full => {
                let r: PnmtRecord = bytemuck::cast([w[0], w[1], w[2], w[3]]);
                r.decode(cell_min, cell)
            }
            _ => {
                if !self.is_some(w) {
                    return None;
                }
                let p = |k: u32| f64::from(w[0] >> (10 * k) & 0x3ff) / 1023.0;
                let s = |k: u32| ((w[1] >> (11 * k) & 0x7ff) as f32 - 1023.0) / 1023.0;
                let uv = if self == Self::Compact {
                    Vec2::new(
                        f16::from_bits(w[2] as u16).to_f32(),
                        f16::from_bits((w[2] >> 16) as u16).to_f32(),
                    )
                } else {
                    Vec2::ZERO
                };
                Some(PnmtHit {
                    position: cell_min + DVec3::new(p(0), p(1), p(2)) * cell,
                    normal: oct_decode(Vec2::new(s(0), s(1))),
                    material: self.material(w),
                    uv,
                })
            }
        }
    }
}

/// One hit record. 16 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Pod, Zeroable)]
#[repr(C)]
pub struct PnmtRecord {
    /// Position in the voxel, quantised.
    pub position: [u16; 3],
    /// Material index, or [`NO_RECORD`].
    pub material: u16,
    /// Octahedral normal, snorm16.
    pub normal: [i16; 2],
    /// Texture coordinates, binary16 bits.
    pub uv: [u16; 2],
}

const _: () = assert!(size_of::<PnmtRecord>() == 16);

/// A decoded record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PnmtHit {
    /// World position.
    pub position: DVec3,
    /// Unit normal.
    pub normal: Vec3,
    /// Material index.
    pub material: u16,
    /// Texture coordinates.
    pub uv: Vec2,
}

/// Octahedral encoding of a direction (of any length: it is divided by its L1 norm) into
/// [-1, 1]².
pub fn oct_encode(n: Vec3) -> Vec2 {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs());
    let p = Vec2::new(n.x, n.y);
    if n.z >= 0.0 {
        p
    } else {
        let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
        Vec2::new((1.0 - p.y.abs()) * sign(p.x), (1.0 - p.x.abs()) * sign(p.y))
    }
}

/// Inverse of [`oct_encode`].
pub fn oct_decode(e: Vec2) -> Vec3 {
    let z = 1.0 - e.x.abs() - e.y.abs();
    let t = (-z).max(0.0);
    let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
    Vec3::new(e.x - t * sign(e.x), e.y - t * sign(e.y), z).normalize()
}

/// `x.round() as u32` (halves away from zero) for 0 ≤ x < 2³², NaN giving 0, without a libm
/// call (the line-space bake makes two records per filled shaft, billions at the fine rows):
/// the fraction x − trunc(x) is exact in floating point.
#[inline(always)]
fn round_unsigned(x: f64) -> u32 {
    let i = x as u32;
    i + (x - f64::from(i) >= 0.5) as u32
}

/// [`PnmtLayout::encode_compact_x8`]: [`PnmtLayout::encode`]'s arithmetic for the compact
/// layouts, operation for operation, eight lanes at a time (positions four at a time in f64).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn compact_x8(
    positions: &[[f32; 8]; 3],
    normals: &[[f32; 8]; 3],
    m: &[u32; 8],
    cell_min: DVec3,
    cell: f64,
) -> ([[u32; 2]; 8], u8) {
    use std::arch::x86_64::*;
    // SAFETY (loads): each array holds eight floats.
    let ld = |a: &[f32; 8]| unsafe { _mm256_loadu_ps(a.as_ptr()) };
    let inv = _mm256_set1_pd(1.0 / cell);
    let (zero_d, one_d, steps) = (_mm256_setzero_pd(), _mm256_set1_pd(1.0), _mm256_set1_pd(1023.0));
    let half_d = _mm256_set1_pd(0.5);
    // round_unsigned((clamp((p − min) · inv, 0, 1)) · 1023) of four lanes, as four i32.
    let quantise = |p: __m128, min: f64| {
        let x = _mm256_mul_pd(_mm256_sub_pd(_mm256_cvtps_pd(p), _mm256_set1_pd(min)), inv);
        let x = _mm256_mul_pd(_mm256_min_pd(_mm256_max_pd(x, zero_d), one_d), steps);
        let i = _mm256_cvttpd_epi32(x);
        let up = _mm256_cmp_pd::<_CMP_GE_OQ>(_mm256_sub_pd(x, _mm256_cvtepi32_pd(i)), half_d);
        _mm_add_epi32(i, _mm256_cvtpd_epi32(_mm256_and_pd(up, one_d)))
    };
    let mut q = [_mm256_setzero_si256(); 3];
    for (k, q) in q.iter_mut().enumerate() {
        let p = ld(&positions[k]);
        let min = cell_min[k];
        let (lo, hi) =
            (quantise(_mm256_castps256_ps128(p), min), quantise(_mm256_extractf128_ps::<1>(p), min));
        *q = _mm256_set_m128i(hi, lo);
    }
    // The octahedral map, then round_signed(clamp(e, −1, 1) · 1023).
    let (nx, ny, nz) = (ld(&normals[0]), ld(&normals[1]), ld(&normals[2]));
    let abs = |v: __m256| _mm256_andnot_ps(_mm256_set1_ps(-0.0), v);
    let l1 = _mm256_add_ps(_mm256_add_ps(abs(nx), abs(ny)), abs(nz));
    let (ex, ey, ez) = (_mm256_div_ps(nx, l1), _mm256_div_ps(ny, l1), _mm256_div_ps(nz, l1));
    let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
    let sign = |v: __m256| _mm256_blendv_ps(_mm256_set1_ps(-1.0), one, _mm256_cmp_ps::<_CMP_GE_OQ>(v, zero));
    let lower = _mm256_cmp_ps::<_CMP_GE_OQ>(ez, zero);
    let fx = _mm256_blendv_ps(_mm256_mul_ps(_mm256_sub_ps(one, abs(ey)), sign(ex)), ex, lower);
    let fy = _mm256_blendv_ps(_mm256_mul_ps(_mm256_sub_ps(one, abs(ex)), sign(ey)), ey, lower);
    let limit = _mm256_set1_ps(f32::MAX);
    let finite = |v: __m256| _mm256_cmp_ps::<_CMP_LE_OQ>(abs(v), limit);
    let valid = _mm256_and_ps(
        _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(l1, zero), finite(l1)),
        _mm256_and_ps(finite(fx), finite(fy)),
    );
    let snorm = _mm256_set1_ps(1023.0);
    let round = |e: __m256| {
        let x = _mm256_mul_ps(_mm256_min_ps(_mm256_max_ps(e, _mm256_set1_ps(-1.0)), one), snorm);
        let i = _mm256_cvttps_epi32(x);
        let f = _mm256_sub_ps(x, _mm256_cvtepi32_ps(i));
        let up = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(f, _mm256_set1_ps(0.5)));
        let down = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LE_OQ>(f, _mm256_set1_ps(-0.5)));
        _mm256_add_epi32(_mm256_add_epi32(_mm256_sub_epi32(i, up), down), _mm256_set1_epi32(1023))
    };
    let (sx, sy) = (round(fx), round(fy));
    // SAFETY: `m` holds eight u32.
    let m = unsafe { _mm256_loadu_si256(m.as_ptr().cast()) };
    let w0 = _mm256_or_si256(
        _mm256_or_si256(q[0], _mm256_slli_epi32::<10>(q[1])),
        _mm256_or_si256(_mm256_slli_epi32::<20>(q[2]), _mm256_slli_epi32::<30>(_mm256_srli_epi32::<10>(m))),
    );
    let w1 = _mm256_or_si256(
        _mm256_or_si256(sx, _mm256_slli_epi32::<11>(sy)),
        _mm256_slli_epi32::<22>(_mm256_and_si256(m, _mm256_set1_epi32(0x3ff))),
    );
    let (mut a, mut b) = ([0u32; 8], [0u32; 8]);
    // SAFETY: each array holds eight u32.
    unsafe {
        _mm256_storeu_si256(a.as_mut_ptr().cast(), w0);
        _mm256_storeu_si256(b.as_mut_ptr().cast(), w1);
    }
    (std::array::from_fn(|k| [a[k], b[k]]), _mm256_movemask_ps(valid) as u8)
}

/// `x.round() as i32` for |x| < 2²³ (the fraction is exact there), NaN giving 0.
#[inline(always)]
fn round_signed(x: f32) -> i32 {
    let i = x as i32;
    let f = x - i as f32;
    i + (f >= 0.5) as i32 - (f <= -0.5) as i32
}

impl PnmtRecord {
    /// Whether the record holds a hit.
    pub fn is_some(&self) -> bool {
        self.material != NO_RECORD
    }

    /// Decodes the record of the voxel with minimum corner `cell_min` and edge `cell`.
    pub fn decode(&self, cell_min: DVec3, cell: f64) -> Option<PnmtHit> {
        if !self.is_some() {
            return None;
        }
        let p =
            DVec3::new(self.position[0] as f64, self.position[1] as f64, self.position[2] as f64) / 65535.0;
        let n = oct_decode(Vec2::new(self.normal[0] as f32 / 32767.0, self.normal[1] as f32 / 32767.0));
        Some(PnmtHit {
            position: cell_min + p * cell,
            normal: n,
            material: self.material,
            uv: Vec2::new(f16::from_bits(self.uv[0]).to_f32(), f16::from_bits(self.uv[1]).to_f32()),
        })
    }

    /// The absent record.
    pub const NONE: PnmtRecord =
        PnmtRecord { position: [0; 3], material: NO_RECORD, normal: [0; 2], uv: [0; 2] };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `count` directions spread evenly over the sphere (a Fibonacci lattice).
    fn sphere(count: u32) -> impl Iterator<Item = Vec3> {
        (0..count).map(move |i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / count as f32;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
    }

    /// The angle between two directions in degrees: atan2(|a × b|, a · b) in f64 (acos of an
    /// f32 dot product near 1 alone errs by 0.02°).
    fn degrees(a: Vec3, b: Vec3) -> f64 {
        let (a, b) = (a.as_dvec3(), b.as_dvec3());
        a.cross(b).length().atan2(a.dot(b)).to_degrees()
    }

    /// The eight-lane compact encoder gives `encode`'s words bit for bit wherever it takes a
    /// lane, and takes every lane with a finite non-zero normal: positions inside, on and beyond
    /// the cell (clamped), at and beside every half step of the position and normal
    /// quantisations, normals of every octant, tiny and huge, zero, infinite and NaN.
    #[test]
    fn eight_lane_compact_records_match_encode() {
        let Some(_) =
            PnmtLayout::encode_compact_x8(&[[0.0; 8]; 3], &[[0.0; 8]; 3], &[0; 8], DVec3::ZERO, 1.0)
        else {
            return;
        };
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut taken, mut lanes) = (0u32, 0u32);
        for case in 0..20_000u32 {
            // In the unit cell at the origin, position 0.5 is step 511.5 exactly (p · 1023 is
            // exact there): the one position half step a single-precision position can hit.
            let (cell_min, cell) =
                if case % 2 == 0 { (DVec3::ZERO, 1.0) } else { (DVec3::new(-3.5, 120.25, 7.0), 0.37) };
            let mut p = [[0f32; 8]; 3];
            let mut n = [[0f32; 8]; 3];
            for k in 0..8 {
                for a in 0..3 {
                    let local = match (case + k as u32) % 4 {
                        // At a half step (or a hair beside it).
                        0 => ((rnd() * 1023.0).floor() + 0.5) / 1023.0 + (rnd() - 0.5) * 1e-9,
                        1 => rnd() * 1.4 - 0.2,
                        2 => [0.0, 0.5, 1.0][(rnd() * 3.0) as usize % 3],
                        _ => rnd(),
                    };
                    p[a][k] = (cell_min[a] + local * cell) as f32;
                    n[a][k] = match (case / 4 + k as u32 + a as u32) % 9 {
                        0 => 0.0,
                        1 => ((rnd() * 2046.0).floor() - 1022.5) as f32 / 1023.0,
                        2 => (rnd() as f32 - 0.5) * 1e-30,
                        3 => (rnd() as f32 - 0.5) * 1e30,
                        _ => rnd() as f32 * 2.0 - 1.0,
                    };
                }
                match case % 97 {
                    0 => n[k % 3][k] = f32::NAN,
                    1 => n[k % 3][k] = f32::INFINITY,
                    2 => (0..3).for_each(|a| n[a][k] = 0.0),
                    _ => {}
                }
            }
            // Materials differing lane by lane, some beyond the layout's largest.
            let materials: [u16; 8] = std::array::from_fn(|k| ((case * 7 + k as u32 * 977) % 5000) as u16);
            let (words, mask) = PnmtLayout::encode_compact_x8(&p, &n, &materials, cell_min, cell).unwrap();
            for k in 0..8 {
                let pos = DVec3::new(p[0][k] as f64, p[1][k] as f64, p[2][k] as f64);
                let normal = Vec3::new(n[0][k], n[1][k], n[2][k]);
                let expected =
                    PnmtLayout::CompactNoUv.encode(pos, normal, materials[k], Vec2::ZERO, cell_min, cell);
                let ordinary = normal.is_finite() && normal != Vec3::ZERO;
                lanes += 1;
                if mask >> k & 1 == 1 {
                    taken += 1;
                    assert_eq!(
                        words[k],
                        [expected[0], expected[1]],
                        "case {case} lane {k}: {pos:?} {normal:?}"
                    );
                } else {
                    assert!(!ordinary, "case {case} lane {k}: a finite normal left out: {normal:?}");
                }
            }
        }
        assert!(taken > lanes * 9 / 10, "{taken} of {lanes} lanes taken");
    }

    /// Normals of any length (unit, and scaled from 1e-30 to 1e30) come back within 0.005° of
    /// their direction; zero, infinite and NaN ones encode +Z.
    #[test]
    fn octahedral_round_trip_is_within_0_005_degrees() {
        let mut worst = 0.0f64;
        for n in sphere(2000) {
            for scale in [1.0, 1e-30, 1e-3, 7.0, 1e30] {
                let w = PnmtLayout::Full.encode(DVec3::ZERO, n * scale, 0, Vec2::ZERO, DVec3::ZERO, 1.0);
                let back = PnmtLayout::Full.decode(&w, DVec3::ZERO, 1.0).unwrap().normal;
                worst = worst.max(degrees(n, back));
            }
        }
        assert!(worst < 0.005, "worst normal error {worst} degrees");
        for n in [Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 1.0), Vec3::new(0.0, f32::NAN, 1.0)] {
            let w = PnmtLayout::Full.encode(DVec3::ZERO, n, 0, Vec2::ZERO, DVec3::ZERO, 1.0);
            assert_eq!(PnmtLayout::Full.decode(&w, DVec3::ZERO, 1.0).unwrap().normal, Vec3::Z, "{n}");
        }
    }

    /// The quick roundings against the standard library's, at and beside every half step of
    /// the ranges the records use, and on a dense sweep.
    #[test]
    fn quick_rounding_matches_round() {
        let mut xs: Vec<f64> = vec![0.0, 65535.0, 0.49999999999999994, f64::NAN];
        for k in 0..65535u32 {
            let half = f64::from(k) + 0.5;
            xs.extend([half, half.next_down(), half.next_up(), f64::from(k)]);
        }
        xs.extend((0..200_000).map(|i| f64::from(i) * 65535.0 / 200_000.0));
        for x in xs {
            assert_eq!(round_unsigned(x), x.round() as u32, "{x}");
        }
        let mut ys: Vec<f32> = vec![0.0, -0.0, 32767.0, -32767.0, 0.49999997, -0.49999997, f32::NAN];
        for k in -32767..32767i32 {
            let half = k as f32 + 0.5;
            ys.extend([half, half.next_down(), half.next_up(), k as f32]);
        }
        ys.extend((0..200_000).map(|i| (i as f32 / 100_000.0 - 1.0) * 32767.0));
        for y in ys {
            assert_eq!(round_signed(y), y.round() as i32, "{y}");
        }
    }

    /// Compact records against the layout's own bounds: positions within half a step (1/2046
    /// of the cell) on every axis, 1e5 from the origin too; normals within 0.12° (half an
    /// 11-bit step of the octahedral square; the worst of these 20,000 directions is 0.116°);
    /// materials exact up to 4094 and clamped there; uv exact in binary16 or dropped.
    #[test]
    fn compact_records_round_trip_within_their_steps() {
        for layout in [PnmtLayout::Compact, PnmtLayout::CompactNoUv] {
            for (min, cell) in [(DVec3::ZERO, 1.0), (DVec3::new(1e5, -3.0, 7.0), 0.037)] {
                let mut worst = 0.0f64;
                for i in 0..=4000u32 {
                    let f = |k: u32| ((i * k) % 4001) as f64 / 4000.0;
                    let p = min + DVec3::new(f(1), f(7), f(113)) * cell;
                    let w = layout.encode(p, Vec3::Z, 0, Vec2::ZERO, min, cell);
                    let hit = layout.decode(&w, min, cell).unwrap();
                    worst = worst.max(((hit.position - p) / cell).abs().max_element());
                }
                assert!(worst <= 0.5 / 1023.0 + 1e-9, "{layout:?}: position error {worst} cells");
            }
            let mut worst = 0.0f64;
            for n in sphere(20000) {
                let w = layout.encode(DVec3::ZERO, n * 3.0, 0, Vec2::ZERO, DVec3::ZERO, 1.0);
                let back = layout.decode(&w, DVec3::ZERO, 1.0).unwrap().normal;
                worst = worst.max(degrees(n, back));
            }
            assert!(worst < 0.12, "{layout:?}: normal error {worst} degrees");
            for (m, want) in
                [(0u16, 0u16), (1, 1), (1023, 1023), (1024, 1024), (4094, 4094), (4095, 4094), (60000, 4094)]
            {
                let w = layout.encode(DVec3::ZERO, Vec3::Z, m, Vec2::new(0.5, -2.0), DVec3::ZERO, 1.0);
                let hit = layout.decode(&w, DVec3::ZERO, 1.0).unwrap();
                let uv = if layout == PnmtLayout::Compact { Vec2::new(0.5, -2.0) } else { Vec2::ZERO };
                assert_eq!((hit.material, hit.uv), (want, uv), "{layout:?}, material {m}");
            }
        }
    }

    /// The words of one record of each layout, worked out by hand from the module's table: the
    /// GLSL decoder reads these bits.
    #[test]
    fn records_hold_the_documented_bits() {
        let (p, m, uv) = (DVec3::new(0.5, 0.25, 1.0), 0xabc, Vec2::new(0.5, 2.0));
        // Position 0.5·1023 = 511.5 rounds (away from zero) to 512, 0.25·1023 = 255.75 to 256;
        // +Z is octahedral (0, 0), snorm11 0 stored as 1023; material 0xabc splits into 0b10
        // (bits 10..12) and 0x2bc; uv 0.5 and 2.0 are binary16 0x3800 and 0x4000.
        let compact =
            [512 | 256 << 10 | 1023 << 20 | 0b10 << 30, 1023 | 1023 << 11 | 0x2bc << 22, 0x4000_3800];
        let w = PnmtLayout::Compact.encode(p, Vec3::Z, m, uv, DVec3::ZERO, 1.0);
        assert_eq!(w, [compact[0], compact[1], compact[2], 0]);
        let w = PnmtLayout::CompactNoUv.encode(p, Vec3::Z, m, uv, DVec3::ZERO, 1.0);
        assert_eq!(w, [compact[0], compact[1], 0, 0]);
        // Full: 0.5·65535 = 32767.5 → 32768, 0.25·65535 = 16383.75 → 16384; snorm16 0 is 0.
        let w = PnmtLayout::Full.encode(p, Vec3::Z, m, uv, DVec3::ZERO, 1.0);
        assert_eq!(w, [32768 | 16384 << 16, 65535 | 0xabc << 16, 0, 0x4000_3800]);
        // Absent records: material all ones, nothing else set.
        assert_eq!(PnmtLayout::Full.none(), [0, 0xffff << 16, 0, 0]);
        assert_eq!(PnmtLayout::Compact.none(), [0b11 << 30, 0x3ff << 22, 0, 0]);
        for (layout, _, _) in PnmtLayout::ALL {
            assert!(layout.decode(&layout.none(), DVec3::ZERO, 1.0).is_none(), "{layout:?}");
            assert_eq!(PnmtLayout::from_code(layout.code()), Some(layout));
        }
        assert_eq!(PnmtLayout::from_code(3), None);
    }

    #[test]
    fn positions_quantise_to_the_cell() {
        let min = DVec3::new(1e5, -3.0, 7.0);
        let p = min + DVec3::new(0.25, 0.5, 0.999) * 0.1;
        let w = PnmtLayout::Full.encode(p, Vec3::X, 3, Vec2::new(0.5, 2.0), min, 0.1);
        let hit = PnmtLayout::Full.decode(&w, min, 0.1).unwrap();
        assert!((hit.position - p).abs().max_element() <= 0.1 / 65535.0);
        assert_eq!((hit.material, hit.uv), (3, Vec2::new(0.5, 2.0)));
        assert!(PnmtRecord::NONE.decode(min, 0.1).is_none());
    }
}
