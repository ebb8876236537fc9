//! Seeded ray sets and the comparison of accelerated queries against brute force, used by
//! `kiln verify --rays`.

use std::collections::BTreeMap;

use glam::Vec3;
use kiln_format::SceneView;
use kiln_format::query::{BruteForce, BvhQuery, Hit, IndexedTriangles, Ray, TriangleSource};
use rayon::prelude::*;
use serde::Serialize;

/// SplitMix64: small, seedable, and identical on every platform.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    /// Uniform in [0, n).
    pub fn below(&mut self, n: usize) -> usize {
        (((self.next_u64() >> 32) * n as u64) >> 32) as usize
    }
    /// Uniform direction on the unit sphere.
    pub fn direction(&mut self) -> Vec3 {
        let z = 2.0 * self.f32() - 1.0;
        let phi = std::f32::consts::TAU * self.f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
    /// Uniform point in a box.
    pub fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        lo + (hi - lo) * Vec3::new(self.f32(), self.f32(), self.f32())
    }
    /// Uniform point on a triangle.
    pub fn on_triangle(&mut self, c: [Vec3; 3]) -> Vec3 {
        let (mut u, mut v) = (self.f32(), self.f32());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        c[0] + (c[1] - c[0]) * u + (c[2] - c[0]) * v
    }
}

/// Kinds of rays in a check set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RayClass {
    /// Random origin in the (expanded) bounds, random direction.
    Random,
    /// Random origin, aimed at a random point of a random triangle.
    Aimed,
    /// Exactly axis-aligned (two zero direction components), through a point of a triangle.
    AxisAligned,
    /// Aimed exactly at a vertex.
    Vertex,
    /// Aimed at the midpoint of an edge.
    Edge,
    /// Running along a triangle's edge, in its plane.
    Grazing,
    /// Starting on a triangle's surface, in a random direction.
    OnSurface,
}

impl RayClass {
    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            RayClass::Random => "random",
            RayClass::Aimed => "aimed",
            RayClass::AxisAligned => "axis-aligned",
            RayClass::Vertex => "vertex",
            RayClass::Edge => "edge",
            RayClass::Grazing => "grazing",
            RayClass::OnSurface => "on-surface",
        }
    }
}

const CLASSES: [RayClass; 7] = [
    RayClass::Random,
    RayClass::Aimed,
    RayClass::AxisAligned,
    RayClass::Vertex,
    RayClass::Edge,
    RayClass::Grazing,
    RayClass::OnSurface,
];

/// Generates `n` rays, cycling through the classes, from `seed`.
pub fn generate(
    tris: &(impl TriangleSource + ?Sized),
    lo: Vec3,
    hi: Vec3,
    n: u64,
    seed: u64,
) -> Vec<(RayClass, Ray)> {
    let ext = (hi - lo).max(Vec3::splat(1e-3 * (hi - lo).max_element().max(1e-6)));
    let (blo, bhi) = (lo - ext * 0.1, hi + ext * 0.1);
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|i| {
            let class = CLASSES[(i % CLASSES.len() as u64) as usize];
            let c = tris.corners(rng.below(tris.len().max(1)));
            let aimed = |rng: &mut Rng, target: Vec3| {
                let o = rng.in_box(blo, bhi);
                let d = (target - o).try_normalize().unwrap_or(Vec3::X);
                Ray::new(o, d, 0.0, f32::INFINITY)
            };
            let ray = match class {
                RayClass::Random => Ray::new(rng.in_box(blo, bhi), rng.direction(), 0.0, f32::INFINITY),
                RayClass::Aimed => {
                    let t = rng.on_triangle(c);
                    aimed(&mut rng, t)
                }
                RayClass::AxisAligned => {
                    let target = rng.on_triangle(c);
                    let axis = rng.below(3);
                    let sign = if rng.f32() < 0.5 { 1.0 } else { -1.0 };
                    let mut o = target;
                    o[axis] = if sign > 0.0 { blo[axis] } else { bhi[axis] };
                    let mut d = Vec3::ZERO;
                    d[axis] = sign;
                    Ray::new(o, d, 0.0, f32::INFINITY)
                }
                RayClass::Vertex => {
                    let k = rng.below(3);
                    aimed(&mut rng, c[k])
                }
                RayClass::Edge => {
                    let k = rng.below(3);
                    aimed(&mut rng, (c[k] + c[(k + 1) % 3]) * 0.5)
                }
                RayClass::Grazing => {
                    let k = rng.below(3);
                    let (a, b) = (c[k], c[(k + 1) % 3]);
                    let d = (b - a).try_normalize().unwrap_or(Vec3::X);
                    Ray::new(a - (b - a) * 0.5, d, 0.0, f32::INFINITY)
                }
                RayClass::OnSurface => Ray::new(rng.on_triangle(c), rng.direction(), 0.0, f32::INFINITY),
            };
            (class, ray)
        })
        .collect()
}

/// How two closest hits compare.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Agreement {
    /// Same triangle and distance, or both miss.
    Same,
    /// Different triangles at the same distance (within tolerance): a shared edge or vertex.
    Tie,
    /// A real disagreement.
    Mismatch,
}

/// Relative tolerance on distances of tied hits.
pub const RELATIVE_TOLERANCE: f32 = 1e-5;

/// Compares an accelerated hit with the reference; `abs_tol` is the absolute distance
/// tolerance (a millionth of the scene diagonal).
pub fn compare(got: Option<Hit>, want: Option<Hit>, abs_tol: f32) -> Agreement {
    match (got, want) {
        (None, None) => Agreement::Same,
        (Some(g), Some(w)) if g.triangle == w.triangle && g.t == w.t => Agreement::Same,
        (Some(g), Some(w)) if (g.t - w.t).abs() <= RELATIVE_TOLERANCE * w.t.abs() + abs_tol => Agreement::Tie,
        _ => Agreement::Mismatch,
    }
}

/// Counts of one ray class.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ClassCounts {
    /// Rays.
    pub rays: u64,
    /// Rays that hit (reference).
    pub hits: u64,
    /// Disagreements.
    pub mismatches: u64,
}

/// Result of a BVH check.
#[derive(Debug, Clone, Serialize)]
pub struct BvhCheck {
    /// Rays traced.
    pub rays: u64,
    /// Seed.
    pub seed: u64,
    /// Rays whose reference closest hit exists.
    pub hits: u64,
    /// Hits on different triangles at equal distance (shared edges and vertices).
    pub ties: u64,
    /// Disagreements: hit vs miss, or different distances.
    pub mismatches: u64,
    /// Relative distance tolerance of ties.
    pub relative_tolerance: f32,
    /// Absolute distance tolerance of ties (scene units).
    pub absolute_tolerance: f32,
    /// Per ray class.
    pub by_class: BTreeMap<String, ClassCounts>,
    /// Up to ten disagreements, described.
    pub examples: Vec<String>,
}

/// Traces `n` rays through the file's BVH and by brute force, and compares closest hits.
pub fn check_bvh(view: &SceneView, n: u64, seed: u64) -> BvhCheck {
    let tris = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let bvh = BvhQuery::new(view.bvh, &tris);
    let brute = BruteForce::new(&tris);
    let (lo, hi) = (Vec3::from(view.manifest.bounds.min), Vec3::from(view.manifest.bounds.max));
    let abs_tol = 1e-6 * (hi - lo).length();
    let rays = generate(&tris, lo, hi, n, seed);
    let results: Vec<(RayClass, Option<Hit>, Agreement, Option<Hit>)> = rays
        .par_iter()
        .map(|(class, ray)| {
            let want = brute.closest_hit(ray);
            let got = bvh.closest_hit(ray);
            (*class, want, compare(got, want, abs_tol), got)
        })
        .collect();
    let mut check = BvhCheck {
        rays: n,
        seed,
        hits: 0,
        ties: 0,
        mismatches: 0,
        relative_tolerance: RELATIVE_TOLERANCE,
        absolute_tolerance: abs_tol,
        by_class: BTreeMap::new(),
        examples: Vec::new(),
    };
    for ((class, want, agreement, got), (_, ray)) in results.iter().zip(&rays) {
        let c = check.by_class.entry(class.name().to_string()).or_default();
        c.rays += 1;
        if want.is_some() {
            c.hits += 1;
            check.hits += 1;
        }
        match agreement {
            Agreement::Same => {}
            Agreement::Tie => check.ties += 1,
            Agreement::Mismatch => {
                c.mismatches += 1;
                check.mismatches += 1;
                if check.examples.len() < 10 {
                    check.examples.push(format!(
                        "{class:?} ray origin {:?} direction {:?}: BVH {:?}, brute force {:?}",
                        ray.origin, ray.direction, got, want
                    ));
                }
            }
        }
    }
    check
}
