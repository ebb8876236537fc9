//! Triangles that span a cell: where a triangle holds the whole section of its plane through the
//! widened cell (a wall, a floor, any triangle much larger than a cell), it meets exactly the
//! shafts that its plane meets, which one side test per patch decides in closed form.
//!
//! Such cells are most of the fine grids of seed 004's table (the Cornell box's walls: 70 % of the
//! 64³ bunny's cells) and of architectural scenes, where the general search spent most of its time
//! finding, window by window, what the plane decides at once.
//!
//! **Why it is exact.** Every widened shaft lies in the widened cell [−m, 1 + m]³, so it meets
//! the triangle iff it meets the plane's section of that cell, that is the plane. A widened shaft
//! is the convex hull of its two widened patches (boxes), so it meets the plane iff its two boxes
//! do not lie strictly on one side of it together. A patch's side comes from the least and
//! greatest signed distance over its widened box (at corners: the distance is affine).
//!
//! **Why it gives the general search's bits.** The section is taken of the cell widened by a
//! further [`SECTION_SLACK`], and a patch within [`SIDE_SLACK`] of the plane is left undecided (its
//! face pair goes to the general search). So every shaft decided here is met or missed by a
//! distance ten thousand times the f64 rounding of either computation, and the general search's
//! separating-axis test, exact up to that rounding, decides it the same way.

use glam::DVec3;
use kiln_format::linespace::index::{face_axis, face_uv_axes};

/// How much wider than the widened cell the section the triangle must hold is, in cells.
const SECTION_SLACK: f64 = 1e-9;

/// How far from the plane (relative to the L1 norm of its normal, in cells) a patch's widened box
/// must lie, or reach beyond it, for its side to be decided here.
const SIDE_SLACK: f64 = 1e-9;

/// The plane of a triangle that spans the widened cell.
#[derive(Debug, Clone, Copy)]
pub struct Span {
    normal: DVec3,
    offset: f64,
    margin: f64,
    /// [`SIDE_SLACK`] scaled by the normal's L1 norm: the least signed distance decided.
    slack: f64,
}

/// The patches of one face by side of the plane: bit `u·n + v` for patch (u, v).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sides {
    /// Patches whose widened box lies wholly on the normal's side.
    pub above: u64,
    /// Patches whose widened box lies wholly on the other side.
    pub below: u64,
}

impl Span {
    /// The plane of the triangle with cell-local corners `v`, if the triangle holds its section of
    /// the cell widened by `margin` (and [`SECTION_SLACK`]).
    pub fn of(v: [DVec3; 3], margin: f64) -> Option<Span> {
        let normal = (v[1] - v[0]).cross(v[2] - v[0]);
        if !normal.is_finite() || normal == DVec3::ZERO {
            return None;
        }
        let offset = normal.dot(v[0]);
        let slack = SIDE_SLACK * normal.abs().element_sum();
        let (lo, hi) = (-margin - SECTION_SLACK, 1.0 + margin + SECTION_SLACK);
        // n × (each edge), corner to next: the edge functions of points of the plane.
        let m = [0, 1, 2].map(|i| normal.cross(v[(i + 1) % 3] - v[i]));
        let inside = |p: DVec3| (0..3).all(|i| m[i].dot(p - v[i]) >= 0.0);
        // The section is the convex hull of the plane's crossings of the box's 12 edges; the
        // triangle (convex) holds it iff it holds them. An edge is crossed where its corners lie
        // on two sides, which is decided only with every corner clear of the plane by the slack
        // (a crossing computed near a corner can round to beyond it and go unchecked).
        let side = |p: DVec3| normal.dot(p) - offset;
        let corner = |c: usize| DVec3::new([lo, hi][c & 1], [lo, hi][c >> 1 & 1], [lo, hi][c >> 2]);
        if (0..8).any(|c| side(corner(c)).abs() <= slack) {
            return None;
        }
        let mut crossings = 0;
        for k in 0..3 {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            for (a, b) in [(lo, lo), (lo, hi), (hi, lo), (hi, hi)] {
                let mut p = DVec3::ZERO;
                p[i] = a;
                p[j] = b;
                p[k] = lo;
                let below = side(p) < 0.0;
                p[k] = hi;
                if below == (side(p) < 0.0) {
                    continue;
                }
                // The corners' sides differ, so normal[k] is not zero, and the crossing lies
                // strictly between them: rounding may only push it to the edge's ends.
                p[k] = ((offset - normal[i] * a - normal[j] * b) / normal[k]).clamp(lo, hi);
                if !inside(p) {
                    return None;
                }
                crossings += 1;
            }
        }
        (crossings >= 3).then_some(Span { normal, offset, margin, slack })
    }

    /// The patches of `face` at `n` × `n` patches by side, or `None` if one lies too near the
    /// plane to be decided here.
    pub fn sides(&self, face: u32, n: u32) -> Option<Sides> {
        let s = 1.0 / n as f64;
        let j = face_axis(face);
        let (ua, va) = face_uv_axes(face);
        let (nl, slack) = (self.normal, self.slack);
        // The widened box of patch (u, v): centre (face mod 2 on j, (index + 1/2)·s on ua and va),
        // half extents (m on j, s/2 + m on ua and va).
        let radius = nl[j].abs() * self.margin + (nl[ua].abs() + nl[va].abs()) * (0.5 * s + self.margin);
        let base = nl[j] * (face % 2) as f64 - self.offset;
        let mut sides = Sides { above: 0, below: 0 };
        for u in 0..n {
            for v in 0..n {
                let centre = base + nl[ua] * ((u as f64 + 0.5) * s) + nl[va] * ((v as f64 + 0.5) * s);
                let (least, most) = (centre - radius, centre + radius);
                if least.abs() <= slack || most.abs() <= slack {
                    return None;
                }
                let bit = 1u64 << (u * n + v);
                if least > 0.0 {
                    sides.above |= bit;
                } else if most < 0.0 {
                    sides.below |= bit;
                }
            }
        }
        Some(sides)
    }
}

/// The patches of face b that the shafts from a patch of face a on side `a` (its bit in
/// `above` or `below`, or neither: it straddles) meet: all but those on the same side.
#[inline(always)]
pub fn met_from(pa_bit: u64, a: &Sides, b: &Sides, all: u64) -> u64 {
    if a.above & pa_bit != 0 {
        all & !b.above
    } else if a.below & pa_bit != 0 {
        all & !b.below
    } else {
        all
    }
}
