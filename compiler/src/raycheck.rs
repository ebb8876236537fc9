//! Seeded ray sets and the comparison of accelerated queries against brute force, used by
//! `kiln verify --rays`.

use std::collections::BTreeMap;

use glam::{DVec3, Vec3};
use kiln_format::SceneView;
use kiln_format::linespace::{LineSpace, Variants};
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
    /// Aimed exactly at a corner of the voxel grid.
    VoxelCorner,
    /// Aimed at the midpoint of an edge of the voxel grid.
    VoxelEdge,
    /// Axis-aligned, lying exactly in a plane between cells.
    FacePlane,
    /// Starting inside a random non-empty cell.
    InsideCell,
    /// A finite segment between two random points (a shadow ray).
    Segment,
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
            RayClass::VoxelCorner => "voxel-corner",
            RayClass::VoxelEdge => "voxel-edge",
            RayClass::FacePlane => "face-plane",
            RayClass::InsideCell => "inside-cell",
            RayClass::Segment => "segment",
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

/// A generated ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RaySample {
    /// Its class.
    pub class: RayClass,
    /// The ray.
    pub ray: Ray,
    /// The triangle it starts on ([`RayClass::OnSurface`]).
    pub origin_triangle: Option<u32>,
}

/// Generates `n` rays, cycling through the classes, from `seed`.
pub fn generate(
    tris: &(impl TriangleSource + ?Sized),
    lo: Vec3,
    hi: Vec3,
    n: u64,
    seed: u64,
) -> Vec<RaySample> {
    let ext = (hi - lo).max(Vec3::splat(1e-3 * (hi - lo).max_element().max(1e-6)));
    let (blo, bhi) = (lo - ext * 0.1, hi + ext * 0.1);
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|i| {
            let class = CLASSES[(i % CLASSES.len() as u64) as usize];
            let tri = rng.below(tris.len().max(1));
            let c = tris.corners(tri);
            let mut origin_triangle = None;
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
                RayClass::OnSurface => {
                    origin_triangle = Some(tri as u32);
                    Ray::new(rng.on_triangle(c), rng.direction(), 0.0, f32::INFINITY)
                }
                _ => unreachable!("grid classes are generated by generate_grid"),
            };
            RaySample { class, ray, origin_triangle }
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
        .map(|r| {
            let want = brute.closest_hit(&r.ray);
            let got = bvh.closest_hit(&r.ray);
            (r.class, want, compare(got, want, abs_tol), got)
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
    for ((class, want, agreement, got), RaySample { ray, .. }) in results.iter().zip(&rays) {
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

/// Line-space checks: rays of every general class plus grid-specific ones (through grid
/// corners and edges, lying in cell planes, starting inside cells, finite segments).
pub fn generate_grid(
    tris: &(impl TriangleSource + ?Sized),
    ls: &LineSpace,
    lo: Vec3,
    hi: Vec3,
    n: u64,
    seed: u64,
) -> Vec<RaySample> {
    let general = generate(tris, lo, hi, n / 2, seed);
    let h = &ls.header;
    let (glo, ghi) = (DVec3::from(h.origin), h.grid_max());
    let ext = (hi - lo).max(Vec3::splat(1e-3 * (hi - lo).max_element().max(1e-6)));
    let (blo, bhi) = (lo - ext * 0.1, hi + ext * 0.1);
    let occupied: Vec<usize> =
        (0..h.cell_count() as usize).filter(|&c| !ls.cell_triangles(c).is_empty()).collect();
    let classes = [
        RayClass::VoxelCorner,
        RayClass::VoxelEdge,
        RayClass::FacePlane,
        RayClass::InsideCell,
        RayClass::Segment,
    ];
    let mut rng = Rng::new(seed ^ 0x5151_5151);
    let grid_point = |rng: &mut Rng| {
        DVec3::new(
            rng.below(h.dims[0] as usize + 1) as f64,
            rng.below(h.dims[1] as usize + 1) as f64,
            rng.below(h.dims[2] as usize + 1) as f64,
        )
    };
    let world = |g: DVec3| (glo + g * h.cell).as_vec3();
    let aimed = |rng: &mut Rng, target: Vec3| {
        let o = rng.in_box(blo, bhi);
        Ray::new(o, (target - o).try_normalize().unwrap_or(Vec3::X), 0.0, f32::INFINITY)
    };
    let mut out = general;
    for i in 0..n - n / 2 {
        let class = classes[(i % classes.len() as u64) as usize];
        let ray = match class {
            RayClass::VoxelCorner => {
                let g = grid_point(&mut rng);
                aimed(&mut rng, world(g))
            }
            RayClass::VoxelEdge => {
                let mut g = grid_point(&mut rng);
                let a = rng.below(3);
                g[a] = (g[a] - 0.5).max(0.5);
                aimed(&mut rng, world(g))
            }
            RayClass::FacePlane => {
                let a = rng.below(3);
                let b = (a + 1 + rng.below(2)) % 3;
                let mut o = rng.in_box(glo.as_vec3(), ghi.as_vec3());
                o[a] = world(grid_point(&mut rng))[a];
                let mut d = Vec3::ZERO;
                d[b] = if rng.f32() < 0.5 { 1.0 } else { -1.0 };
                o[b] = if d[b] > 0.0 { blo[b] } else { bhi[b] };
                Ray::new(o, d, 0.0, f32::INFINITY)
            }
            RayClass::InsideCell => {
                let c = h.cell_coords(
                    occupied[rng.below(occupied.len().max(1)).min(occupied.len().saturating_sub(1))],
                );
                let cmin = h.cell_min(c).as_vec3();
                let o = rng.in_box(cmin, cmin + Vec3::splat(h.cell as f32));
                Ray::new(o, rng.direction(), 0.0, f32::INFINITY)
            }
            _ => {
                let (a, b) = (rng.in_box(blo, bhi), rng.in_box(blo, bhi));
                Ray::new(a, (b - a).try_normalize().unwrap_or(Vec3::X), 0.0, (b - a).length())
            }
        };
        out.push(RaySample { class, ray, origin_triangle: None });
    }
    out
}

/// Median, 99th percentile and maximum.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Spread {
    /// Median.
    pub median: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Maximum.
    pub max: f64,
}

impl Spread {
    fn of(mut v: Vec<f64>) -> Spread {
        if v.is_empty() {
            return Spread::default();
        }
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
        Spread { median: at(0.5), p99: at(0.99), max: at(1.0) }
    }
}

/// Candidate-list results.
#[derive(Debug, Clone, Default, Serialize)]
pub struct CandidateCheck {
    /// Closest hits that disagree with brute force (hit vs miss, or different distance).
    pub mismatches: u64,
    /// Different triangles at equal distance.
    pub ties: u64,
    /// Any-hit answers that disagree with brute force.
    pub any_hit_mismatches: u64,
    /// Up to ten disagreements.
    pub examples: Vec<String>,
}

/// Binary line-space results (conservative any-hit within each ray's interval).
#[derive(Debug, Clone, Default, Serialize)]
pub struct BinaryCheck {
    /// Rays brute force says hit something that the bits call empty: must be 0.
    pub false_misses: u64,
    /// Rays the bits call blocked that hit nothing (the price of one bit per shaft).
    pub false_hits: u64,
    /// Rays that hit something (brute force).
    pub hits: u64,
    /// Up to ten false misses.
    pub examples: Vec<String>,
}

/// PNMT results against the exact closest hit (origin triangle excluded for rays leaving a
/// surface).
#[derive(Debug, Clone, Default, Serialize)]
pub struct PnmtCheck {
    /// Rays where exactly one of PNMT and the reference reports a hit.
    pub hit_disagreements: u64,
    /// PNMT hit, reference miss.
    pub pnmt_only: u64,
    /// Reference hit, PNMT miss.
    pub reference_only: u64,
    /// Rays where both hit.
    pub both_hit: u64,
    /// Distance from PNMT's point to the reference hit, scene units.
    pub position_error: Spread,
    /// Angle between PNMT's normal and the shading normal at the reference hit, degrees.
    pub normal_error_degrees: Spread,
}

/// Result of a line-space check.
#[derive(Debug, Clone, Serialize)]
pub struct LineSpaceCheck {
    /// Rays traced.
    pub rays: u64,
    /// Seed.
    pub seed: u64,
    /// Candidate lists, if present.
    pub candidates: Option<CandidateCheck>,
    /// Binary line space.
    pub binary: BinaryCheck,
    /// PNMT, if present.
    pub pnmt: Option<PnmtCheck>,
    /// Rays per class.
    pub by_class: BTreeMap<String, u64>,
}

/// Exact closest hit that skips `exclude` (the surface a ray starts on).
fn closest_excluding(brute: &BruteForce, ray: &Ray, exclude: Option<u32>) -> Option<Hit> {
    let mut r = *ray;
    for _ in 0..8 {
        let h = brute.closest_hit(&r)?;
        if Some(h.triangle) != exclude {
            return Some(h);
        }
        r.tmin = h.t.next_up();
    }
    None
}

/// Traces `n` rays through every line-space variant present and compares with brute force.
pub fn check_line_space(view: &SceneView, ls: &LineSpace, n: u64, seed: u64) -> LineSpaceCheck {
    let tris = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let brute = BruteForce::new(&tris);
    let (lo, hi) = (Vec3::from(view.manifest.bounds.min), Vec3::from(view.manifest.bounds.max));
    let abs_tol = 1e-6 * (hi - lo).length();
    let rays = generate_grid(&tris, ls, lo, hi, n, seed);
    let has_cand = ls.has(Variants::CANDIDATES);
    let has_pnmt = ls.has(Variants::PNMT);
    let shading_normal = |h: &Hit| {
        let [a, b, c] =
            view.triangles[h.triangle as usize].map(|i| Vec3::from(view.vertices[i as usize].normal));
        (a * (1.0 - h.u - h.v) + b * h.u + c * h.v).normalize_or(Vec3::Z)
    };
    /// PNMT outcome of one ray: (position and normal errors when both hit, PNMT hit, reference hit).
    type PnmtOutcome = (Option<(f64, f64)>, bool, bool);
    struct One {
        cand: Option<(Agreement, bool, Option<Hit>)>,
        binary: bool,
        reference: Option<Hit>,
        pnmt: Option<PnmtOutcome>,
    }
    let results: Vec<One> = rays
        .par_iter()
        .map(|r| {
            let reference = brute.closest_hit(&r.ray);
            let cand = has_cand.then(|| {
                let got = ls.closest_hit(&tris, &r.ray);
                (compare(got, reference, abs_tol), ls.any_hit(&tris, &r.ray) != reference.is_some(), got)
            });
            let pnmt = has_pnmt.then(|| {
                let want = closest_excluding(&brute, &r.ray, r.origin_triangle);
                let normal = r.origin_triangle.map(|t| {
                    let [a, b, c] = tris.corners(t as usize);
                    let n = (b - a).cross(c - a).normalize_or(Vec3::Z);
                    if n.dot(r.ray.direction) < 0.0 { -n } else { n }
                });
                let got = ls.pnmt_hit(&r.ray, normal);
                let errors = match (&got, &want) {
                    (Some(g), Some(w)) => {
                        let p = r.ray.at(w.t).as_dvec3();
                        let angle = g.hit.normal.dot(shading_normal(w)).clamp(-1.0, 1.0).acos().to_degrees();
                        Some(((g.hit.position - p).length(), angle as f64))
                    }
                    _ => None,
                };
                (errors, got.is_some(), want.is_some())
            });
            One { cand, binary: ls.any_hit_binary(&r.ray), reference, pnmt }
        })
        .collect();
    let mut check = LineSpaceCheck {
        rays: rays.len() as u64,
        seed,
        candidates: has_cand.then(CandidateCheck::default),
        binary: BinaryCheck::default(),
        pnmt: has_pnmt.then(PnmtCheck::default),
        by_class: BTreeMap::new(),
    };
    let (mut pos, mut ang) = (Vec::new(), Vec::new());
    for (one, r) in results.iter().zip(&rays) {
        *check.by_class.entry(r.class.name().to_string()).or_default() += 1;
        let hit = one.reference.is_some();
        check.binary.hits += hit as u64;
        if hit && !one.binary {
            check.binary.false_misses += 1;
            if check.binary.examples.len() < 10 {
                check.binary.examples.push(format!("{:?}: {:?} hits {:?}", r.class, r.ray, one.reference));
            }
        }
        check.binary.false_hits += (!hit && one.binary) as u64;
        if let (Some(c), Some((agreement, any_bad, got))) = (&mut check.candidates, one.cand) {
            match agreement {
                Agreement::Same => {}
                Agreement::Tie => c.ties += 1,
                Agreement::Mismatch => {
                    c.mismatches += 1;
                    if c.examples.len() < 10 {
                        c.examples.push(format!(
                            "{:?}: {:?}: candidates {got:?}, brute force {:?}",
                            r.class, r.ray, one.reference
                        ));
                    }
                }
            }
            c.any_hit_mismatches += any_bad as u64;
        }
        if let (Some(p), Some((errors, got, want))) = (&mut check.pnmt, one.pnmt) {
            p.pnmt_only += (got && !want) as u64;
            p.reference_only += (!got && want) as u64;
            if let Some((e, a)) = errors {
                p.both_hit += 1;
                pos.push(e);
                ang.push(a);
            }
        }
    }
    if let Some(p) = &mut check.pnmt {
        p.hit_disagreements = p.pnmt_only + p.reference_only;
        p.position_error = Spread::of(pos);
        p.normal_error_degrees = Spread::of(ang);
    }
    check
}
