//! CPU queries of baked structures: rays against triangles, through the BVH or by brute force.
//!
//! These are the ground truth that `kiln verify` and the tests hold every accelerated query to,
//! and the reference the GPU traversal mirrors.

mod brute;
mod bvh;
mod ray;
mod triangle;

pub use brute::BruteForce;
pub use bvh::{BvhQuery, TraversalStats};
pub use ray::Ray;
pub use triangle::{TriangleHit, intersect_triangle};

use glam::Vec3;

/// A ray's closest (or any) hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray direction (in units of the direction's length).
    pub t: f32,
    /// Triangle index (into `TRIS`).
    pub triangle: u32,
    /// Barycentric coordinate of vertex 1.
    pub u: f32,
    /// Barycentric coordinate of vertex 2.
    pub v: f32,
}

/// Triangles given as positions, indexable by triangle number.
pub trait TriangleSource: Sync {
    /// Number of triangles.
    fn len(&self) -> usize;
    /// Whether there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The three corners of triangle `i`.
    fn corners(&self, i: usize) -> [Vec3; 3];
}

/// Triangles of a validated scene: vertex positions and index triples.
#[derive(Debug, Clone, Copy)]
pub struct IndexedTriangles<'a> {
    /// Vertices.
    pub vertices: &'a [crate::sections::Vertex],
    /// Index triples (validated to be in range).
    pub triangles: &'a [[u32; 3]],
}

impl TriangleSource for IndexedTriangles<'_> {
    fn len(&self) -> usize {
        self.triangles.len()
    }
    fn corners(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|v| Vec3::from(self.vertices[v as usize].position))
    }
}

impl TriangleSource for [[Vec3; 3]] {
    fn len(&self) -> usize {
        <[[Vec3; 3]]>::len(self)
    }
    fn corners(&self, i: usize) -> [Vec3; 3] {
        self[i]
    }
}

/// Closest hit by testing every triangle: the reference for all accelerated queries. Among
/// hits at the same distance the lowest triangle index wins.
pub fn closest_hit_brute_force(tris: &(impl TriangleSource + ?Sized), ray: &Ray) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    let mut tmax = ray.tmax;
    for i in 0..tris.len() {
        if let Some(h) = intersect_triangle(ray, tris.corners(i), tmax)
            && best.is_none_or(|b| h.t < b.t)
        {
            tmax = h.t;
            best = Some(Hit { t: h.t, triangle: i as u32, u: h.u, v: h.v });
        }
    }
    best
}

/// Whether any triangle is hit within the ray's interval, by testing every triangle.
pub fn any_hit_brute_force(tris: &(impl TriangleSource + ?Sized), ray: &Ray) -> bool {
    (0..tris.len()).any(|i| intersect_triangle(ray, tris.corners(i), ray.tmax).is_some())
}

/// Moves a ray origin `p` off the surface with geometric normal `n` by a few units in the last
/// place of each coordinate, proportional to the coordinate's magnitude (Wächter and Binder,
/// "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems, ch. 6): robust at
/// every scale, unlike a fixed epsilon. `n` must point to the side the ray leaves into.
pub fn offset_origin(p: Vec3, n: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let of = (n * INT_SCALE).to_array().map(|x| x as i32);
    let pi: [f32; 3] = std::array::from_fn(|a| {
        let bits = p[a].to_bits() as i32;
        f32::from_bits(bits.wrapping_add(if p[a] < 0.0 { -of[a] } else { of[a] }) as u32)
    });
    Vec3::from(std::array::from_fn::<f32, 3, _>(|a| {
        if p[a].abs() < ORIGIN { p[a] + FLOAT_SCALE * n[a] } else { pi[a] }
    }))
}
