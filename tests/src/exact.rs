//! An exact ray–triangle reference, written apart from `kiln_format::query::intersect_triangle`
//! so that the query tests do not judge that function by itself.
//!
//! Every `f32` is a dyadic rational `m · 2^e`, so differences, products and sums of the ray's and
//! the corners' coordinates are computed here without rounding (big integers, [`Dyadic`]). The
//! ray `o + t d` meets the **closed** triangle `p0 p1 p2` (edges and corners included) exactly
//! when the three edge volumes `d · ((p_i − o) × (p_j − o))` over the edges (1,2), (2,0), (0,1)
//! are all ≥ 0 or all ≤ 0 and the ray is not parallel to the plane; their sum is
//! `d · ((p1 − p0) × (p2 − p0))`, zero exactly when it is. The hit is at
//! `t = det(p0 − o, p1 − o, p2 − o) / (d · n)`.
//!
//! A watertight test promises that a ray through an edge hits at least one of the triangles
//! sharing it and a ray through a vertex at least one of those around it. The closed triangle is
//! the convention that makes an exact test watertight: on a shared edge both triangles hit. The
//! production test works on rounded, sheared `f32` coordinates, so near an edge it may answer
//! either way for each triangle; [`Judgement::near`] marks those rays, where only the closed
//! mesh as a whole can be judged.
//!
//! Double precision is used first as a filter (Shewchuk's idea): a volume whose `f64` value is
//! far above its rounding bound has that sign; only the rest are computed exactly.

use std::cmp::Ordering;

use glam::{DVec3, Vec3};

/// An exact integer: sign and magnitude (little-endian 32-bit limbs, no high zero limbs).
#[derive(Debug, Clone, PartialEq, Eq)]
struct Int {
    negative: bool,
    magnitude: Vec<u32>,
}

impl Int {
    /// `m · 2^shift`.
    fn shifted(m: i64, shift: u32) -> Int {
        let mut magnitude = vec![0u32; (shift / 32) as usize];
        let bits = u128::from(m.unsigned_abs()) << (shift % 32);
        magnitude.extend([bits as u32, (bits >> 32) as u32, (bits >> 64) as u32, (bits >> 96) as u32]);
        Int::normalised(m < 0, magnitude)
    }

    fn normalised(negative: bool, mut magnitude: Vec<u32>) -> Int {
        while magnitude.last() == Some(&0) {
            magnitude.pop();
        }
        Int { negative: negative && !magnitude.is_empty(), magnitude }
    }

    fn signum(&self) -> Ordering {
        match (self.magnitude.is_empty(), self.negative) {
            (true, _) => Ordering::Equal,
            (false, true) => Ordering::Less,
            (false, false) => Ordering::Greater,
        }
    }

    fn compare_magnitudes(a: &[u32], b: &[u32]) -> Ordering {
        a.len().cmp(&b.len()).then_with(|| a.iter().rev().cmp(b.iter().rev()))
    }

    fn add(&self, other: &Int) -> Int {
        let (a, b) = (&self.magnitude, &other.magnitude);
        if self.negative == other.negative {
            let mut out = Vec::with_capacity(a.len().max(b.len()) + 1);
            let mut carry = 0u64;
            for i in 0..a.len().max(b.len()) {
                let s = u64::from(*a.get(i).unwrap_or(&0)) + u64::from(*b.get(i).unwrap_or(&0)) + carry;
                out.push(s as u32);
                carry = s >> 32;
            }
            out.push(carry as u32);
            return Int::normalised(self.negative, out);
        }
        // Opposite signs: the larger magnitude minus the smaller, with the larger one's sign.
        let (big, small, negative) = match Int::compare_magnitudes(a, b) {
            Ordering::Less => (b, a, other.negative),
            _ => (a, b, self.negative),
        };
        let mut out = Vec::with_capacity(big.len());
        let mut borrow = 0i64;
        for (i, &limb) in big.iter().enumerate() {
            let mut d = i64::from(limb) - i64::from(*small.get(i).unwrap_or(&0)) - borrow;
            borrow = i64::from(d < 0);
            if d < 0 {
                d += 1 << 32;
            }
            out.push(d as u32);
        }
        Int::normalised(negative, out)
    }

    fn mul(&self, other: &Int) -> Int {
        let (a, b) = (&self.magnitude, &other.magnitude);
        let mut out = vec![0u32; a.len() + b.len()];
        for (i, &x) in a.iter().enumerate() {
            let mut carry = 0u64;
            for (j, &y) in b.iter().enumerate() {
                let s = u64::from(out[i + j]) + u64::from(x) * u64::from(y) + carry;
                out[i + j] = s as u32;
                carry = s >> 32;
            }
            out[i + b.len()] = carry as u32;
        }
        Int::normalised(self.negative != other.negative, out)
    }

    /// The nearest `f64` to `self · 2^exponent`, up to a few units in the last place.
    fn to_f64(&self, exponent: i32) -> f64 {
        let n = self.magnitude.len();
        let top = self.magnitude.iter().enumerate().skip(n.saturating_sub(3));
        let v: f64 = top.map(|(i, &l)| f64::from(l) * 2f64.powi(32 * i as i32 + exponent)).sum();
        if self.negative { -v } else { v }
    }
}

/// An exact dyadic rational `m · 2^e`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Dyadic {
    m: Int,
    e: i32,
}

impl Dyadic {
    /// The exact value of an `f32` (which must be finite).
    pub fn from_f32(x: f32) -> Dyadic {
        assert!(x.is_finite(), "the exact reference takes finite inputs, not {x}");
        let bits = x.to_bits();
        let (biased, fraction) = ((bits >> 23) & 0xff, i64::from(bits & 0x7f_ffff));
        let (m, e) = if biased == 0 { (fraction, -149) } else { (fraction | 1 << 23, biased as i32 - 150) };
        Dyadic { m: Int::shifted(if bits >> 31 == 1 { -m } else { m }, 0), e }
    }

    /// With exponent `e` (at most `self.e`), the same value.
    fn at(&self, e: i32) -> Int {
        let shift = (self.e - e) as u32;
        self.m.mul(&Int::shifted(1, shift))
    }

    /// `self + other`.
    pub fn add(&self, other: &Dyadic) -> Dyadic {
        let e = self.e.min(other.e);
        Dyadic { m: self.at(e).add(&other.at(e)), e }
    }

    /// `self − other`.
    pub fn sub(&self, other: &Dyadic) -> Dyadic {
        self.add(&other.neg())
    }

    /// `−self`.
    pub fn neg(&self) -> Dyadic {
        let mut m = self.m.clone();
        m.negative = !m.negative && !m.magnitude.is_empty();
        Dyadic { m, e: self.e }
    }

    /// `self · other`.
    pub fn mul(&self, other: &Dyadic) -> Dyadic {
        Dyadic { m: self.m.mul(&other.m), e: self.e + other.e }
    }

    /// Its sign.
    pub fn signum(&self) -> Ordering {
        self.m.signum()
    }

    /// Its value rounded to `f64` (products of three `f32` values never leave its range).
    pub fn to_f64(&self) -> f64 {
        self.m.to_f64(self.e)
    }
}

type D3 = [Dyadic; 3];

fn exact3(v: Vec3) -> D3 {
    v.to_array().map(Dyadic::from_f32)
}

fn sub3(a: &D3, b: &D3) -> D3 {
    std::array::from_fn(|i| a[i].sub(&b[i]))
}

fn cross3(a: &D3, b: &D3) -> D3 {
    let c = |i: usize, j: usize| a[i].mul(&b[j]).sub(&a[j].mul(&b[i]));
    [c(1, 2), c(2, 0), c(0, 1)]
}

fn dot3(a: &D3, b: &D3) -> Dyadic {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

/// The sign of `d · (a × b)` with `a = p − o`, `b = q − o`, exactly: from `f64` when its value
/// clears the rounding bound, else from [`Dyadic`] arithmetic. The bound: `p − o` in `f64` is
/// off by at most 2⁻⁵³ (|p| + |o|), and the six products and five sums of the triple product add
/// at most about 10 · 2⁻⁵³ of `|d| (|a| + |p| + |o|) (|b| + |q| + |o|)`; 10⁻¹² of it is far
/// above both.
fn volume_sign(o: Vec3, d: Vec3, p: Vec3, q: Vec3) -> (Ordering, f64) {
    let (od, pd, qd, dd) = (o.as_dvec3(), p.as_dvec3(), q.as_dvec3(), d.as_dvec3());
    let (a, b) = (pd - od, qd - od);
    let v = dd.dot(a.cross(b));
    let bound = 1e-12
        * dd.length()
        * (a.length() + pd.length() + od.length())
        * (b.length() + qd.length() + od.length());
    if v.abs() > bound {
        return (v.partial_cmp(&0.0).expect("finite"), v);
    }
    let (o, a, b) = (exact3(o), exact3(p), exact3(q));
    let exact = dot3(&exact3(d), &cross3(&sub3(&a, &o), &sub3(&b, &o)));
    (exact.signum(), exact.to_f64())
}

/// What the exact reference says of one ray and one triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Judgement {
    /// The ray meets the closed triangle with `tmin <= t < tmax`: decided exactly.
    pub closed_hit: bool,
    /// The ray's line passes exactly through an edge or a corner of the triangle (an edge
    /// volume is exactly zero, the others agree): a closed hit on the boundary if the crossing
    /// is within the interval.
    pub on_boundary: bool,
    /// Within rounding reach of the boundary, of the interval's ends, or nearly parallel to
    /// the plane: an `f32` test may answer either way here (see [`NEAR`]).
    pub near: bool,
    /// Ray parameter of the plane crossing: exact rounded to `f64` where the line meets the
    /// closed triangle, an `f64` estimate elsewhere (NaN when parallel).
    pub t: f64,
    /// The smallest `t` at which a rounded test could report a hit on this triangle when
    /// [`near`](Self::near) holds: the ray's passage by the triangle's reach.
    pub t_first: f64,
    /// How far an `f32` test's `t` may stray from [`t`](Self::t) on a clear hit: [`T_ROUNDING`]
    /// times the corners' reach over cos θ, in units of `|d|`.
    pub t_reach: f64,
}

/// The relative rounding of an `f32` test's corners that [`Judgement::t_reach`] allows for: a
/// few times 2⁻²⁴, moving the crossing along the ray by that much of the reach over cos θ.
pub const T_ROUNDING: f64 = 1e-6;

/// The relative rounding that [`Judgement::near`] allows for: corners moved by `NEAR` times
/// their distance from the origin, the direction tilted by `NEAR`, the crossing moved by `NEAR`
/// times the triangle's reach, or a direction within `NEAR` radians of the plane. The
/// production test's sheared coordinates are off by a few times 2⁻²⁴ ≈ 6e-8 of those
/// magnitudes, so 10⁻⁵ leaves a wide margin.
pub const NEAR: f64 = 1e-5;

/// Judges the ray `origin + t direction`, `tmin <= t < tmax`, against the triangle `p`.
pub fn judge(origin: Vec3, direction: Vec3, tmin: f32, tmax: f32, p: [Vec3; 3]) -> Judgement {
    // Edge volumes over the edges (1,2), (2,0), (0,1).
    let edges = [(1, 2), (2, 0), (0, 1)];
    let volumes = edges.map(|(i, j)| volume_sign(origin, direction, p[i], p[j]));
    let (od, dd) = (origin.as_dvec3(), direction.as_dvec3());
    let a: [DVec3; 3] = p.map(|q| q.as_dvec3() - od);
    // A corner's reach: its distance, widened where `f32` rounds `p − o` (by the rounding over
    // NEAR, so that such a rounding alone makes the ray near).
    let extent: [f64; 3] =
        std::array::from_fn(|i| a[i].length() + ((p[i] - origin).as_dvec3() - a[i]).length() / NEAR);
    let size = extent.iter().fold(0.0f64, |m, &x| m.max(x));
    // Each volume's sign where it clears its rounding reach, else zero. Moving corner i by δ
    // changes the volume d · (a_i × a_j) by d · (δ × a_j), at most |δ| ρ_j |d| with ρ_j the
    // distance of corner j from the ray's line; tilting d by a relative ε changes it by at most
    // ε |d| |a_i × a_j|. With |δ| up to NEAR times a corner's reach and ε up to NEAR, the reach
    // of rounding is NEAR |d| (r_i ρ_j + r_j ρ_i + |a_i × a_j| + NEAR r_i r_j).
    let rho: [f64; 3] = std::array::from_fn(|i| a[i].cross(dd).length() / dd.length());
    let clear = edges.iter().zip(&volumes).map(|(&(i, j), &(s, v))| {
        let reach = NEAR
            * dd.length()
            * (extent[i] * rho[j]
                + extent[j] * rho[i]
                + a[i].cross(a[j]).length()
                + NEAR * extent[i] * extent[j]);
        if v.abs() <= reach { Ordering::Equal } else { s }
    });
    let clear: Vec<Ordering> = clear.collect();
    let refuted = clear.contains(&Ordering::Less) && clear.contains(&Ordering::Greater);
    let confirmed =
        clear.iter().all(|&s| s == Ordering::Less) || clear.iter().all(|&s| s == Ordering::Greater);
    let near_edge = !refuted && !confirmed;
    let den_estimate: f64 = volumes.iter().map(|(_, v)| v).sum();
    let n = (a[1] - a[0]).cross(a[2] - a[0]);
    let grazing = !(den_estimate.abs() > NEAR * n.length() * dd.length());
    let signs = volumes.map(|(s, _)| s);
    let line_meets =
        signs.iter().all(|&s| s != Ordering::Less) || signs.iter().all(|&s| s != Ordering::Greater);
    // The volumes sum to d · n, so all-zero volumes are a ray in the plane.
    let in_plane = signs.iter().all(|&s| s == Ordering::Equal);
    let (closed_hit, t) = if line_meets && !in_plane {
        // The line meets the closed triangle and d · n is not zero (its sign is that of the
        // non-zero volumes): the crossing, exactly.
        let (o, q) = (exact3(origin), p.map(exact3));
        let den = dot3(&exact3(direction), &cross3(&sub3(&q[1], &q[0]), &sub3(&q[2], &q[0])));
        let num = dot3(&sub3(&q[0], &o), &cross3(&sub3(&q[1], &o), &sub3(&q[2], &o)));
        // t >= bound exactly when (num − bound · den) · sign(den) >= 0.
        let after = |bound: f32| {
            let s = num.sub(&Dyadic::from_f32(bound).mul(&den)).signum();
            if den.signum() == Ordering::Less { s.reverse() } else { s }
        };
        let inside =
            after(tmin) != Ordering::Less && (tmax == f32::INFINITY || after(tmax) == Ordering::Less);
        (inside, num.to_f64() / den.to_f64())
    } else {
        // A miss; an f64 estimate of the crossing orders it among near triangles.
        (false, a[0].dot(a[1].cross(a[2])) / den_estimate)
    };
    let t = if t.is_finite() { t } else { f64::NAN };
    // Moving the corners by δ moves the crossing along the ray by up to |δ| / cos θ (θ between
    // the ray and the normal): near an end when that end's point lies within NEAR times the
    // reach of the plane.
    let cos = den_estimate.abs() / (n.length() * dd.length());
    let near_end = |bound: f32| (t - f64::from(bound)).abs() * dd.length() * cos <= NEAR * size;
    let at_end = near_end(tmin) || (tmax != f32::INFINITY && near_end(tmax));
    // Where along the ray a rounded test could place a hit: a point of the triangle's reach
    // near the line, measured along d or along one axis of d (at most √3 ρ apart); nearly
    // parallel to the plane, it could be any of them.
    let along = |i: usize, side: f64| {
        (a[i].dot(dd) / dd.length() + side * (2.0 * rho[i] + NEAR * size)) / dd.length()
    };
    let t_first = (0..3).map(|i| along(i, -1.0)).fold(f64::INFINITY, f64::min);
    let t_last = (0..3).map(|i| along(i, 1.0)).fold(f64::NEG_INFINITY, f64::max);
    // Wholly before tmin or after tmax: no test in f32 reaches it, however near an edge.
    let outside = t_last < f64::from(tmin) || t_first >= f64::from(tmax);
    // Clear of the line: every point of the triangle lies within its longest edge of each
    // corner, so at least ρ_i − that edge from the line; rounding moves the corners by NEAR
    // times the reach and tilts the line by NEAR, which moves a point of the reach by as much
    // again. A triangle smaller than NEAR of its distance has every edge volume within
    // rounding reach, whichever way the line passes, and would otherwise be near every ray.
    let longest = (0..3).map(|i| (a[(i + 1) % 3] - a[i]).length()).fold(0.0f64, f64::max);
    let clear_of_line = rho.iter().fold(0.0f64, |m, &r| m.max(r)) - longest > 4.0 * NEAR * size;
    let near = !clear_of_line && (t.is_nan() || at_end || (line_meets && grazing) || (near_edge && !outside));
    let on_boundary = line_meets && !in_plane && signs.contains(&Ordering::Equal);
    let t_reach = T_ROUNDING * size / (cos * dd.length());
    let t_reach = if t_reach.is_nan() { f64::INFINITY } else { t_reach };
    Judgement { closed_hit, on_boundary, near, t, t_first, t_reach }
}

/// The reference's closest hit of a ray among `tris`, where it decides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Closest {
    /// No triangle is hit, and none is near.
    Miss,
    /// The closest hit: every hit at a smaller or equal distance (within `tolerance`) is clear
    /// of the boundary, and no near triangle could come first.
    Hit {
        /// Ray parameter.
        t: f64,
        /// How far an `f32` test's distance may stray from it ([`Judgement::t_reach`]).
        reach: f64,
    },
    /// A near triangle could be the closest hit, or could hide nothing: undecided.
    Undecided,
}

/// The closest hit of the ray `origin + t direction` (`tmin <= t < tmax`) among `tris`, where
/// the exact reference decides it; a near triangle within `relative · t + absolute` of the
/// closest clear hit (the tolerance of ties, widened by the hit's `t_reach`) leaves it
/// undecided.
pub fn closest(
    origin: Vec3,
    direction: Vec3,
    tmin: f32,
    tmax: f32,
    tris: impl IntoIterator<Item = [Vec3; 3]>,
    relative: f64,
    absolute: f64,
) -> Closest {
    let (mut best, mut reach) = (f64::INFINITY, 0.0);
    let mut near_first: Option<f64> = None;
    for tri in tris {
        let j = judge(origin, direction, tmin, tmax, tri);
        if j.near {
            let t = if j.t_first.is_nan() { f64::NEG_INFINITY } else { j.t_first };
            near_first = Some(near_first.map_or(t, |n| n.min(t)));
        } else if j.closed_hit && j.t < best {
            (best, reach) = (j.t, j.t_reach);
        }
    }
    match near_first {
        Some(n) if !best.is_finite() || n <= best + relative * best.abs() + absolute + reach => {
            Closest::Undecided
        }
        _ if best.is_finite() => Closest::Hit { t: best, reach },
        _ => Closest::Miss,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dyadic_arithmetic_is_exact() {
        // 1 + 2⁻⁴⁰ − 1 is 2⁻⁴⁰, which f32 and f64 sums of these inputs both lose or keep only
        // by luck; products of subnormals stay exact.
        let one = Dyadic::from_f32(1.0);
        let tiny = Dyadic::from_f32(2f32.powi(-40));
        assert_eq!(one.add(&tiny).sub(&one).to_f64(), 2f64.powi(-40));
        let sub = Dyadic::from_f32(f32::from_bits(1));
        assert_eq!(sub.mul(&sub).mul(&sub).to_f64(), 2f64.powi(-447));
        assert_eq!(Dyadic::from_f32(-3.5).mul(&Dyadic::from_f32(2.0)).to_f64(), -7.0);
        assert_eq!(Dyadic::from_f32(1e30).sub(&Dyadic::from_f32(1e30)).signum(), Ordering::Equal);
        let big = Dyadic::from_f32(f32::MAX);
        assert_eq!(big.mul(&big).sub(&big.mul(&big)).signum(), Ordering::Equal);
        assert_eq!(big.mul(&big).to_f64(), f64::from(f32::MAX) * f64::from(f32::MAX));
    }

    #[test]
    fn edges_and_corners_are_closed() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let down = Vec3::NEG_Z;
        let at = |x: f32, y: f32| judge(Vec3::new(x, y, 1.0), down, 0.0, f32::INFINITY, tri);
        let inside = at(0.25, 0.25);
        assert!(inside.closed_hit && !inside.on_boundary && !inside.near && inside.t == 1.0);
        for (x, y) in [(0.5, 0.0), (0.0, 0.5), (0.5, 0.5), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
            let j = at(x, y);
            assert!(j.closed_hit && j.on_boundary && j.near, "({x}, {y}): {j:?}");
        }
        // Just outside the hypotenuse by one unit in the last place.
        let j = at(0.5, f32::from_bits(0.5f32.to_bits() + 1));
        assert!(!j.closed_hit && !j.on_boundary && j.near, "{j:?}");
        let far = at(2.0, 2.0);
        assert!(!far.closed_hit && !far.near);
        // Behind the origin, beyond tmax, and parallel.
        assert!(!judge(Vec3::new(0.2, 0.2, 1.0), Vec3::Z, 0.0, f32::INFINITY, tri).closed_hit);
        assert!(!judge(Vec3::new(0.2, 0.2, 1.0), down, 0.0, 1.0, tri).closed_hit);
        assert!(judge(Vec3::new(0.2, 0.2, 1.0), down, 0.0, 1.0000001, tri).closed_hit);
        let grazing = judge(Vec3::new(-1.0, 0.2, 0.0), Vec3::X, 0.0, f32::INFINITY, tri);
        assert!(!grazing.closed_hit && grazing.near && grazing.t.is_nan());
    }

    #[test]
    fn tiny_triangles_are_near_only_to_rays_that_pass_by() {
        // Edges of 3e-5 a unit away: below NEAR of their distance, so every edge volume is
        // within rounding reach. A line half a unit away is still a clear miss; one through
        // the triangle or a few of its sizes away is near.
        let tri = [Vec3::new(0.0, 0.0, -1.0), Vec3::new(3e-5, 0.0, -1.0), Vec3::new(0.0, 3e-5, -1.0)];
        let o = Vec3::ZERO;
        let towards = |x: f32, y: f32| judge(o, Vec3::new(x, y, -1.0).normalize(), 0.0, f32::INFINITY, tri);
        for (x, y) in [(0.5, 0.0), (-0.3, 0.4), (0.0, -0.01), (1e-3, 1e-3)] {
            let j = towards(x, y);
            assert!(!j.closed_hit && !j.near, "({x}, {y}): {j:?}");
        }
        for (x, y) in [(1e-5, 1e-5), (-1e-5, 0.0), (4e-5, 4e-5)] {
            assert!(towards(x, y).near, "({x}, {y})");
        }
        // Crossing its plane beside it, at the ray's start: not near either.
        let beside = judge(Vec3::new(0.5, 0.0, -1.0), Vec3::Z, 0.0, f32::INFINITY, tri);
        assert!(!beside.near, "{beside:?}");
    }
}
