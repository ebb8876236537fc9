//! Queries through the line space: a 3D-DDA over cells, and in each non-empty cell the shaft the
//! ray's line passes through.
//!
//! **Which shaft.** The line `o + t·d` enters a cell through the face whose slab it enters last
//! and leaves through the face whose slab it leaves first (ties go to the lower axis); the entry
//! and exit points, clamped to their faces, give the patches. The segment of the line inside the
//! cell lies in the convex hull of the two patches, so every triangle it can hit meets that shaft.
//!
//! **Self-hits.** There is no "voxel offset". Candidate queries are exact: a ray leaving a
//! surface sets `tmin` (or offsets its origin) exactly as for the BVH and gets the same answer.
//! Binary queries are conservative: a filled shaft in the start cell counts as a hit. A PNMT
//! record is accepted only if its stored point `p` lies in the ray's interval
//! (`tmin ≤ (p − o)·d / |d|² ≤ tmax`) and, for rays leaving a surface with geometric normal `n`
//! (oriented to the side the ray leaves into), strictly in front of that surface's tangent plane:
//! `(p − o)·n > q`, where `q` is the record's quantisation step (cell · √3 / 65535, or / 1023 in
//! the compact layouts) plus the grid margin. Records of the origin's own plane are thus
//! rejected, while other surfaces, including the far side of a concave one, are accepted.

use glam::{DVec3, Vec3};

use super::index::{face_uv_axes, patch_of, shaft};
use super::{Dda, LineSpace, NO_SLOT, PnmtHit, entry};
use crate::query::{Hit, Ray, TriangleSource, intersect_triangle};

/// The shaft a line passes through in one cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaftLookup {
    /// Shaft number within the cell.
    pub shaft: u32,
    /// Whether the line runs from the pair's lower face to its higher face.
    pub front: bool,
    /// Key direction `n_b − n_a` of the pair (outward normals), in cell units.
    pub key_dir: DVec3,
    /// Smallest key over the cell.
    pub key_lo: f64,
}

/// A PNMT hit with the ray parameter of its stored point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PnmtQueryHit {
    /// `(p − o)·d / |d|²` of the stored point.
    pub t: f64,
    /// The record.
    pub hit: PnmtHit,
}

impl super::GridHeader {
    /// Slack of the candidate lists' early exit in cell units: keys are compared against the
    /// key of the best hit so far, which the single-precision triangle test may place up to a
    /// margin off the true surface.
    pub fn key_eps(&self) -> f64 {
        4.0 * self.margin / self.cell + 1e-9
    }

    /// How far in front of the origin's surface a PNMT record must lie to be accepted (the
    /// position quantisation step plus the margin; see the module documentation).
    pub fn pnmt_step(&self) -> f64 {
        let steps = self.pnmt_records().unwrap_or_default().position_steps();
        self.cell * 3f64.sqrt() / steps + self.margin
    }
}

/// Outward normal of a face as a vector.
fn outward(face: u32) -> DVec3 {
    let mut n = DVec3::ZERO;
    n[(face / 2) as usize] = if face.is_multiple_of(2) { -1.0 } else { 1.0 };
    n
}

impl LineSpace<'_> {
    /// The shaft of the line of `ray` in `cell`; `None` if the line misses the cell (it may
    /// still pass within the margin of it: callers then test every triangle of the cell).
    pub fn lookup(&self, cell: [u32; 3], ray: &Ray) -> Option<ShaftLookup> {
        let h = &self.header;
        let p = (ray.origin.as_dvec3() - h.cell_min(cell)) / h.cell;
        let d = ray.direction.as_dvec3() / h.cell;
        let (mut near, mut far) = ([f64::NEG_INFINITY; 3], [f64::INFINITY; 3]);
        for a in 0..3 {
            if d[a] != 0.0 {
                let (t0, t1) = ((0.0 - p[a]) / d[a], (1.0 - p[a]) / d[a]);
                near[a] = t0.min(t1);
                far[a] = t0.max(t1);
            }
        }
        let ea =
            (0..3).filter(|&a| d[a] != 0.0).max_by(|&x, &y| near[x].total_cmp(&near[y]).then(y.cmp(&x)))?;
        let xa =
            (0..3).filter(|&a| d[a] != 0.0).min_by(|&x, &y| far[x].total_cmp(&far[y]).then(x.cmp(&y)))?;
        if near[ea] > far[xa] {
            return None;
        }
        let entry_face = 2 * ea as u32 + (d[ea] < 0.0) as u32;
        let exit_face = 2 * xa as u32 + (d[xa] > 0.0) as u32;
        let n = h.shaft_res;
        let patch = |face: u32, t: f64| {
            let q = p + d * t;
            let (u, v) = face_uv_axes(face);
            patch_of(q[u], q[v], n)
        };
        let (s, front) =
            shaft(entry_face, patch(entry_face, near[ea]), exit_face, patch(exit_face, far[xa]), n)?;
        let (fa, fb) = if front { (entry_face, exit_face) } else { (exit_face, entry_face) };
        let key_dir = outward(fb) - outward(fa);
        Some(ShaftLookup { shaft: s, front, key_dir, key_lo: key_dir.min(DVec3::ZERO).element_sum() })
    }

    /// Closest hit through the candidate lists: exactly the brute-force answer (up to ties).
    pub fn closest_hit(&self, tris: &(impl TriangleSource + ?Sized), ray: &Ray) -> Option<Hit> {
        self.trace(tris, ray, false)
    }

    /// Whether anything is hit in `[tmin, tmax)`, through the candidate lists (exact).
    pub fn any_hit(&self, tris: &(impl TriangleSource + ?Sized), ray: &Ray) -> bool {
        self.trace(tris, ray, true).is_some()
    }

    fn trace(&self, tris: &(impl TriangleSource + ?Sized), ray: &Ray, any: bool) -> Option<Hit> {
        let h = &self.header;
        let d_len = ray.direction.as_dvec3().length();
        let margin_t = h.margin / d_len * 2.0;
        let key_eps = h.key_eps();
        let mut best: Option<Hit> = None;
        for visit in Dda::new(h, ray.origin, ray.direction, ray.tmin, ray.tmax) {
            if best.is_some_and(|b| visit.t_enter > b.t as f64 + margin_t) {
                break;
            }
            let c = h.cell_index(visit.cell);
            let slot = self.slots[c];
            if slot == NO_SLOT {
                continue;
            }
            let cell_tris = self.cell_triangles(c);
            let test = |t: u32, best: &mut Option<Hit>| {
                let tmax = best.map_or(ray.tmax, |b| b.t);
                if let Some(hit) = intersect_triangle(ray, tris.corners(t as usize), tmax)
                    && best.is_none_or(|b| hit.t < b.t || (hit.t == b.t && t < b.triangle))
                {
                    *best = Some(Hit { t: hit.t, triangle: t, u: hit.u, v: hit.v });
                }
            };
            let Some(l) = self.lookup(visit.cell, ray) else {
                for &t in cell_tris {
                    test(t, &mut best);
                }
                continue;
            };
            let Some(rank) = self.rank(slot, l.shaft) else { continue };
            let list = self.entries(rank);
            let cell_min = h.cell_min(visit.cell);
            let key_of = |b: &Hit| {
                let p = (ray.origin.as_dvec3() + ray.direction.as_dvec3() * b.t as f64 - cell_min) / h.cell;
                p.dot(l.key_dir)
            };
            let dequant = |q: u32| l.key_lo + q as f64 * (2.0 / 255.0);
            if l.front {
                for &e in list {
                    if let Some(b) = &best
                        && dequant(entry::key_min(e)) > key_of(b) + key_eps
                    {
                        break;
                    }
                    test(cell_tris[entry::local(e) as usize], &mut best);
                    if any && best.is_some() {
                        return best;
                    }
                }
            } else {
                for &e in list.iter().rev() {
                    if let Some(b) = &best
                        && dequant(entry::prefix_key_max(e)) < key_of(b) - key_eps
                    {
                        break;
                    }
                    test(cell_tris[entry::local(e) as usize], &mut best);
                    if any && best.is_some() {
                        return best;
                    }
                }
            }
        }
        best
    }

    /// Conservative any-hit through the shaft bits: true if the ray passes through a filled
    /// shaft of any cell it meets within `[tmin, tmax]`. Never false when a triangle is hit.
    pub fn any_hit_binary(&self, ray: &Ray) -> bool {
        let h = &self.header;
        Dda::new(h, ray.origin, ray.direction, ray.tmin, ray.tmax).any(|visit| {
            let slot = self.slots[h.cell_index(visit.cell)];
            slot != NO_SLOT && self.lookup(visit.cell, ray).is_none_or(|l| self.rank(slot, l.shaft).is_some())
        })
    }

    /// Approximate closest hit from PNMT records (see the module documentation for the
    /// acceptance rule). `origin_normal`: the geometric normal of the surface the ray leaves.
    pub fn pnmt_hit(&self, ray: &Ray, origin_normal: Option<Vec3>) -> Option<PnmtQueryHit> {
        let h = &self.header;
        let o = ray.origin.as_dvec3();
        let d = ray.direction.as_dvec3();
        let q = h.pnmt_step();
        for visit in Dda::new(h, ray.origin, ray.direction, ray.tmin, ray.tmax) {
            let slot = self.slots[h.cell_index(visit.cell)];
            if slot == NO_SLOT {
                continue;
            }
            let Some(l) = self.lookup(visit.cell, ray) else { continue };
            let Some(rank) = self.rank(slot, l.shaft) else { continue };
            let record = self.record(rank, !l.front);
            let Some(hit) = self.pnmt_layout.decode(record, h.cell_min(visit.cell), h.cell) else { continue };
            let t = (hit.position - o).dot(d) / d.length_squared();
            let in_front = origin_normal.is_none_or(|n| (hit.position - o).dot(n.as_dvec3()) > q);
            if t >= ray.tmin as f64 && t <= ray.tmax as f64 && in_front {
                return Some(PnmtQueryHit { t, hit });
            }
        }
        None
    }
}
