//! Brute force over every triangle, with a conservative bounding-sphere prefilter laid out for
//! vectorisation: it is the reference for accelerated queries, and fast enough to check
//! 10⁵ rays against 10⁵ triangles on a laptop.

use glam::Vec3;

use super::{Hit, Ray, TriangleSource, intersect_triangle};

/// All triangles with their bounding spheres (structure of arrays).
#[derive(Debug, Clone)]
pub struct BruteForce {
    corners: Vec<[Vec3; 3]>,
    cx: Vec<f32>,
    cy: Vec<f32>,
    cz: Vec<f32>,
    /// Radius, already widened for rounding (see `new`).
    r: Vec<f32>,
}

impl BruteForce {
    /// Precomputes spheres. Centres are corner means; radii are the largest corner distance,
    /// widened by 1e-5 relative plus 1e-5 of the centre's magnitude, which bounds the rounding
    /// of the f32 prefilter arithmetic for every ray within the supported coordinate range.
    pub fn new(tris: &(impl TriangleSource + ?Sized)) -> BruteForce {
        let n = tris.len();
        let mut b = BruteForce {
            corners: Vec::with_capacity(n),
            cx: Vec::with_capacity(n),
            cy: Vec::with_capacity(n),
            cz: Vec::with_capacity(n),
            r: Vec::with_capacity(n),
        };
        for i in 0..n {
            let c = tris.corners(i);
            let centre = (c[0].as_dvec3() + c[1].as_dvec3() + c[2].as_dvec3()) / 3.0;
            let radius = c.iter().map(|p| (p.as_dvec3() - centre).length()).fold(0.0, f64::max);
            let widened = radius * (1.0 + 1e-5) + 1e-5 * centre.length() + f64::from(f32::MIN_POSITIVE);
            b.corners.push(c);
            b.cx.push(centre.x as f32);
            b.cy.push(centre.y as f32);
            b.cz.push(centre.z as f32);
            b.r.push(widened as f32);
        }
        b
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.corners.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.corners.is_empty()
    }

    /// Closest hit; among equal distances the lowest triangle index wins.
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut tmax = ray.tmax;
        self.candidates(ray, |i| {
            if let Some(h) = intersect_triangle(ray, self.corners[i], tmax)
                && best.is_none_or(|b| h.t < b.t)
            {
                // Candidates come in index order and equal distances fail `t < tmax`, so the
                // lowest index wins ties.
                tmax = h.t;
                best = Some(Hit { t: h.t, triangle: i as u32, u: h.u, v: h.v });
            }
        });
        best
    }

    /// Whether any triangle is hit within the ray's interval.
    pub fn any_hit(&self, ray: &Ray) -> bool {
        let mut hit = false;
        self.candidates(ray, |i| hit |= !hit && intersect_triangle(ray, self.corners[i], ray.tmax).is_some());
        hit
    }

    /// Calls `f` with every triangle whose sphere the ray's line passes within (in index order).
    fn candidates(&self, ray: &Ray, mut f: impl FnMut(usize)) {
        let (o, d) = (ray.origin, ray.direction);
        let d2 = d.length_squared();
        let slack = 1e-5 * o.length();
        const CHUNK: usize = 64;
        let n = self.len();
        let mut mask = [false; CHUNK];
        let mut start = 0;
        while start < n {
            let end = (start + CHUNK).min(n);
            let (cx, cy, cz, r) =
                (&self.cx[start..end], &self.cy[start..end], &self.cz[start..end], &self.r[start..end]);
            for k in 0..end - start {
                let (wx, wy, wz) = (cx[k] - o.x, cy[k] - o.y, cz[k] - o.z);
                // |w × d|² ≤ (r + slack)² |d|²: the line passes within the widened sphere.
                let (px, py, pz) = (wy * d.z - wz * d.y, wz * d.x - wx * d.z, wx * d.y - wy * d.x);
                let rr = r[k] + slack;
                mask[k] = px * px + py * py + pz * pz <= rr * rr * d2 * (1.0 + 1e-5);
            }
            for (k, &m) in mask[..end - start].iter().enumerate() {
                if m {
                    f(start + k);
                }
            }
            start = end;
        }
    }
}
