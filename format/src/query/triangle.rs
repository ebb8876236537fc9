//! Watertight ray–triangle intersection (Woop, Benthin, Wald: "Watertight Ray/Triangle
//! Intersection", JCGT 2013): a ray through a shared edge or vertex hits at least one of the
//! triangles sharing it, whatever the direction. Both faces are hit (no culling).

use glam::Vec3;

use super::Ray;

/// Where a ray meets a triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter.
    pub t: f32,
    /// Barycentric weight of corner 1.
    pub u: f32,
    /// Barycentric weight of corner 2.
    pub v: f32,
}

/// Intersects `ray` with the triangle `p`, accepting hits with `ray.tmin <= t < tmax`
/// (`tmax` replaces the ray's own so that closest-hit searches can shrink it).
pub fn intersect_triangle(ray: &Ray, p: [Vec3; 3], tmax: f32) -> Option<TriangleHit> {
    let [kx, ky, kz] = ray.k;
    let s = ray.shear;
    let a = p[0] - ray.origin;
    let b = p[1] - ray.origin;
    let c = p[2] - ray.origin;
    let ax = a[kx] - s.x * a[kz];
    let ay = a[ky] - s.y * a[kz];
    let bx = b[kx] - s.x * b[kz];
    let by = b[ky] - s.y * b[kz];
    let cx = c[kx] - s.x * c[kz];
    let cy = c[ky] - s.y * c[kz];
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    // On an edge the single-precision products can round to zero with the wrong sign;
    // recompute exactly enough in double precision (the paper's fallback).
    if u == 0.0 || v == 0.0 || w == 0.0 {
        let (ax, ay, bx, by, cx, cy) = (ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64);
        u = (cx * by - cy * bx) as f32;
        v = (ax * cy - ay * cx) as f32;
        w = (bx * ay - by * ax) as f32;
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let az = s.z * a[kz];
    let bz = s.z * b[kz];
    let cz = s.z * c[kz];
    let t_scaled = u * az + v * bz + w * cz;
    let inv = 1.0 / det;
    let t = t_scaled * inv;
    if !(t >= ray.tmin && t < tmax) {
        return None;
    }
    Some(TriangleHit { t, u: v * inv, v: w * inv })
}
