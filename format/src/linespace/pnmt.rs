//! PNMT records: position, normal, material and texture coordinates of the front or back hit
//! of a shaft's midpoint ray, in 16 bytes.
//!
//! | bytes | field | encoding | precision |
//! |---|---|---|---|
//! | 0..6 | position | u16 × 3, the voxel [0, 1]³ mapped to 0..65535 | cell / 65535 per axis |
//! | 6..8 | material | u16; 0xFFFF = no record | exact |
//! | 8..12 | normal | octahedral (Meyer et al. 2010), snorm16 × 2 | < 0.005° |
//! | 12..16 | uv | f16 × 2 | 11-bit mantissa |
//!
//! The thesis stored 16 half floats per shaft (32 bytes, world positions in half precision); kiln
//! stores the same 32 bytes per filled shaft (front and back), positions relative to the voxel.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec2, Vec3};
use half::f16;

/// Material value of an absent record.
pub const NO_RECORD: u16 = 0xffff;

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

/// `x.round() as i32` for |x| < 2²³ (the fraction is exact there), NaN giving 0.
#[inline(always)]
fn round_signed(x: f32) -> i32 {
    let i = x as i32;
    let f = x - i as f32;
    i + (f >= 0.5) as i32 - (f <= -0.5) as i32
}

impl PnmtRecord {
    /// Encodes a hit in the voxel with minimum corner `cell_min` and edge `cell`. `normal` need
    /// not be of unit length (+Z where it is zero or not finite).
    pub fn encode(
        position: DVec3,
        normal: Vec3,
        material: u16,
        uv: Vec2,
        cell_min: DVec3,
        cell: f64,
    ) -> PnmtRecord {
        // One division, not three: they were a quarter of the encoding's time in the bake.
        let local = ((position - cell_min) * (1.0 / cell)).clamp(DVec3::ZERO, DVec3::ONE);
        let q = |x: f64| round_unsigned(x * 65535.0) as u16;
        // The octahedral map divides by the L1 norm, so any finite non-zero direction will do,
        // unit or not (normalising it first was a tenth of the PNMT bake). A zero or non-finite
        // one maps to NaN, which the rounding below makes 0: +Z.
        let e = oct_encode(normal);
        let s = |x: f32| round_signed(x.clamp(-1.0, 1.0) * 32767.0) as i16;
        PnmtRecord {
            position: [q(local.x), q(local.y), q(local.z)],
            material: material.min(NO_RECORD - 1),
            normal: [s(e.x), s(e.y)],
            uv: [f16::from_f32(uv.x).to_bits(), f16::from_f32(uv.y).to_bits()],
        }
    }

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

    /// Normals of any length (unit, and scaled from 1e-30 to 1e30) come back within 0.005° of
    /// their direction; zero, infinite and NaN ones encode +Z.
    #[test]
    fn octahedral_round_trip_is_within_0_005_degrees() {
        let mut worst = 0.0f64;
        for i in 0..2000 {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 2000.0;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            for scale in [1.0, 1e-30, 1e-3, 7.0, 1e30] {
                let rec = PnmtRecord::encode(DVec3::ZERO, n * scale, 0, Vec2::ZERO, DVec3::ZERO, 1.0);
                let back = rec.decode(DVec3::ZERO, 1.0).unwrap().normal;
                // atan2(|a × b|, a · b) in f64: acos of an f32 dot product near 1 alone errs by 0.02°.
                let (a, b) = (n.as_dvec3(), back.as_dvec3());
                worst = worst.max(a.cross(b).length().atan2(a.dot(b)).to_degrees());
            }
        }
        assert!(worst < 0.005, "worst normal error {worst} degrees");
        for n in [Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 1.0), Vec3::new(0.0, f32::NAN, 1.0)] {
            let rec = PnmtRecord::encode(DVec3::ZERO, n, 0, Vec2::ZERO, DVec3::ZERO, 1.0);
            assert_eq!(rec.decode(DVec3::ZERO, 1.0).unwrap().normal, Vec3::Z, "{n}");
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

    #[test]
    fn positions_quantise_to_the_cell() {
        let min = DVec3::new(1e5, -3.0, 7.0);
        let p = min + DVec3::new(0.25, 0.5, 0.999) * 0.1;
        let rec = PnmtRecord::encode(p, Vec3::X, 3, Vec2::new(0.5, 2.0), min, 0.1);
        let hit = rec.decode(min, 0.1).unwrap();
        assert!((hit.position - p).abs().max_element() <= 0.1 / 65535.0);
        assert_eq!((hit.material, hit.uv), (3, Vec2::new(0.5, 2.0)));
        assert!(PnmtRecord::NONE.decode(min, 0.1).is_none());
    }
}
