//! The probe bake's path tracer on the CPU: the light arriving at a point from a direction, split
//! into what the player's direct pass may compute itself (emissive surfaces seen directly) and
//! the rest (the sky, and everything surfaces reflect: every bounce of every emitter kind).
//!
//! - Paths start at the probe, continue by cosine-weighted sampling of the surface's BRDF (full
//!   Cook–Torrance evaluated, so glossy surfaces reflect with the right weight; the sampling is
//!   diffuse) and end by Russian roulette after [`ROULETTE_AFTER`] events, at most
//!   [`MAX_BOUNCES`].
//! - At every surface vertex: the analytic lights by kiln's direct shading (`crate::shading`,
//!   shadow rays through the BVH; one of a rect light's 16 stratified samples, at random) and the emissive triangles by next-event estimation (one
//!   triangle by power, a uniform point on it), combined with the BRDF-sampled hits of emitters by
//!   the balance heuristic. A miss sees the sky (the environment's map where there is one).
//! - Emissive triangles emit from their front face (counter-clockwise), and from both faces when
//!   their material is double-sided, as in the player's path tracer. Alpha is not tested: every
//!   triangle is opaque to the bake.
//!
//! Random numbers come from a stream per (probe, path) ([`path_rng`]), so that the bytes do not
//! depend on thread count or order.

use glam::{Vec2, Vec3};
use kiln_format::query::{BvhQuery, Hit, IndexedTriangles, Ray};
use kiln_format::sections::MaterialFlags;

use crate::raycheck::Rng;
use crate::shading::{ShadingScene, Surface, light_samples};

/// Scattering events after which paths continue only by Russian roulette.
pub const ROULETTE_AFTER: u32 = 3;
/// Scattering events a path counts at most.
pub const MAX_BOUNCES: u32 = 64;

/// `p` moved off its surface along unit `n` by 8 units in the last place of its largest
/// coordinate: enough for a hit point interpolated from its triangle's corners (a few ulps off
/// the plane) not to find its own triangle again, and relative to the magnitude, not absolute nor
/// the shared `offset_origin`'s 256 ulps (2 units at 10⁵, as wide as a room there: the furnace
/// 10⁴ away lost 9 % of its light to paths restarted outside their walls).
fn offset(p: Vec3, n: Vec3) -> Vec3 {
    let scale = p.abs().max_element().max(f32::MIN_POSITIVE) * (8.0 * f32::EPSILON);
    p + n * scale
}

/// The random stream of path `path` of probe `probe` (the compiler's SplitMix64 generator,
/// seeded by both).
pub fn path_rng(probe: u32, path: u32) -> Rng {
    Rng::new(((probe as u64) << 32 | path as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x2545_f491_4f6c_dd1d)
}

/// Direction `i` of `n` spread evenly over the sphere (spherical Fibonacci points).
pub fn fibonacci_direction(i: u32, n: u32) -> Vec3 {
    let golden = (1.0 + 5f32.sqrt()) / 2.0;
    let z = 1.0 - (2.0 * i as f32 + 1.0) / n as f32;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * (i as f32 / golden).fract();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Emissive triangles, chosen in proportion to their power (a cumulative table searched).
#[derive(Debug, Default)]
struct Emitters {
    /// Triangle (stored order) per entry.
    triangles: Vec<u32>,
    /// Cumulative probabilities, the last 1.
    cdf: Vec<f32>,
    /// Probability of choosing each triangle (0 for non-emitters), by triangle.
    pdf: Vec<f32>,
}

/// A ray's first surface, as shading reads it.
#[derive(Debug, Clone, Copy)]
pub struct SurfaceHit {
    /// Distance along the unit ray.
    pub t: f32,
    /// The point.
    pub p: Vec3,
    /// Unit geometric normal, of the counter-clockwise front face.
    pub ng: Vec3,
    /// Unit shading normal.
    pub n: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Material.
    pub material: u32,
    /// Triangle (stored order).
    pub triangle: u32,
    /// Area of the triangle.
    pub area: f32,
}

/// The light from beyond the scene: a constant sky or the baked environment.
#[derive(Debug, Clone, Copy)]
pub enum Sky<'a> {
    /// The same radiance in every direction.
    Constant(Vec3),
    /// The environment's map.
    Environment(&'a crate::bake::environment::BakedEnvironment),
}

impl Sky<'_> {
    /// Radiance arriving from unit direction `d`.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        match self {
            Sky::Constant(l) => *l,
            Sky::Environment(e) => e.view().radiance(d),
        }
    }

    /// Whether it has a sampling table (next-event estimation of the sky).
    pub fn sampled(&self) -> bool {
        matches!(self, Sky::Environment(_))
    }

    /// Solid-angle density of the table's draw of `d` (0 without a table).
    pub fn pdf(&self, d: Vec3) -> f32 {
        match self {
            Sky::Constant(_) => 0.0,
            Sky::Environment(e) => e.view().pdf(d),
        }
    }

    /// Draw `j` of `count` from the table (stratified: draw j's first uniform lies in
    /// [j, j + 1) / count, so that the draws fall on the table's cells in proportion to their
    /// probabilities, not by chance), its radiance and density.
    pub fn sample(&self, j: u32, count: u32, rng: &mut crate::raycheck::Rng) -> Option<(Vec3, Vec3, f32)> {
        let Sky::Environment(e) = self else { return None };
        let view = e.view();
        let first = ((j as f32 + rng.f32()) / count as f32).min(1.0 - f32::EPSILON);
        let (d, pdf) = view.sample([first, rng.f32(), rng.f32()])?;
        Some((d, view.radiance(d), pdf))
    }
}

/// The side of a surface a ray meets ([`Tracer::side`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The side its winding faces.
    Front,
    /// The back of a single-sided surface: the inside of something.
    SingleBack,
    /// The back of a double-sided surface by its winding: the inside of a closed mesh its
    /// author marked double-sided (most exporters' default), or the far side of an open sheet.
    DoubleBack,
}

/// What the bake traces against.
pub struct Tracer<'a> {
    /// Materials, textures, lights, BVH.
    pub shading: ShadingScene<'a>,
    /// Texture coordinates per vertex (empty: none).
    pub uvs: &'a [[f32; 2]],
    /// Material per stored triangle.
    pub triangle_materials: &'a [u32],
    /// What a ray that leaves the scene sees.
    pub sky: Sky<'a>,
    tris: IndexedTriangles<'a>,
    emitters: Emitters,
    /// The least perceptual roughness of the surfaces the paths meet (path regularisation).
    min_roughness: f32,
}

impl std::fmt::Debug for Tracer<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Tracer").field("emitters", &self.emitters.triangles.len()).finish()
    }
}

impl<'a> Tracer<'a> {
    /// A tracer over `shading`'s scene; emissive triangles enter the emitter table by their
    /// emitted luminance (`luminance`: the mean over each triangle of factor × emissive texture,
    /// where a texture modulates it; else the factor's) × area; the texture is read where a
    /// sample lands.
    pub fn new(
        shading: ShadingScene<'a>,
        uvs: &'a [[f32; 2]],
        triangle_materials: &'a [u32],
        sky: Sky<'a>,
        luminance: Option<&[f32]>,
        min_roughness: f32,
    ) -> Tracer<'a> {
        let tris = IndexedTriangles { vertices: shading.vertices, triangles: shading.triangles };
        let mut emitters = Emitters { pdf: vec![0.0; shading.triangles.len()], ..Default::default() };
        let mut power = Vec::new();
        for (t, &m) in triangle_materials.iter().enumerate() {
            let e = Vec3::from(shading.materials[m as usize].emission);
            let [a, b, c] = kiln_format::query::TriangleSource::corners(&tris, t);
            let l = luminance
                .and_then(|l| l.get(t).copied())
                .unwrap_or(kiln_format::gpu::luminance(e.to_array()));
            let p = if e == Vec3::ZERO { 0.0 } else { l * 0.5 * (b - a).cross(c - a).length() };
            if p > 0.0 && p.is_finite() {
                emitters.triangles.push(t as u32);
                power.push(p as f64);
            }
        }
        let total: f64 = power.iter().sum();
        let mut sum = 0.0;
        for (&t, &p) in emitters.triangles.iter().zip(&power) {
            sum += p;
            emitters.cdf.push((sum / total) as f32);
            emitters.pdf[t as usize] = (p / total) as f32;
        }
        if let Some(last) = emitters.cdf.last_mut() {
            *last = 1.0;
        }
        Tracer { shading, uvs, triangle_materials, sky, tris, emitters, min_roughness }
    }

    /// Whether the scene has emissive triangles.
    pub fn has_emitters(&self) -> bool {
        !self.emitters.triangles.is_empty()
    }

    fn query(&self) -> BvhQuery<'_, IndexedTriangles<'a>> {
        BvhQuery::new(self.shading.bvh, &self.tris)
    }

    /// The surface `hit` of a unit ray along `d`.
    fn surface_hit(&self, d: Vec3, hit: Hit) -> SurfaceHit {
        let tri = self.shading.triangles[hit.triangle as usize];
        let v = tri.map(|i| self.shading.vertices[i as usize]);
        let [a, b, c] = v.map(|v| Vec3::from(v.position));
        let cross = (b - a).cross(c - a);
        let w = [1.0 - hit.u - hit.v, hit.u, hit.v];
        let ng = cross.normalize_or(-d);
        let n = (Vec3::from(v[0].normal) * w[0]
            + Vec3::from(v[1].normal) * w[1]
            + Vec3::from(v[2].normal) * w[2])
            .normalize_or(ng);
        let uv = if self.uvs.is_empty() {
            Vec2::ZERO
        } else {
            tri.iter().zip(w).map(|(&i, w)| Vec2::from(self.uvs[i as usize]) * w).sum()
        };
        SurfaceHit {
            t: hit.t,
            // From the corners, not o + d·t: its error is a few ulps of the point, not of the
            // origin and the distance.
            p: a * w[0] + b * w[1] + c * w[2],
            ng,
            n,
            uv,
            material: self.triangle_materials[hit.triangle as usize],
            triangle: hit.triangle,
            area: 0.5 * cross.length(),
        }
    }

    /// The first surface along the unit ray from `o` (a free point: no offset) along `d`.
    pub fn trace(&self, o: Vec3, d: Vec3, tmax: f32) -> Option<SurfaceHit> {
        self.query().closest_hit(&Ray::new(o, d, 0.0, tmax)).map(|h| self.surface_hit(d, h))
    }

    /// Whether the segment from `p` (on a surface of geometric normal `ng`) along unit `d` is
    /// blocked within `tmax`.
    fn occluded(&self, p: Vec3, ng: Vec3, d: Vec3, tmax: f32) -> bool {
        let o = offset(p, if ng.dot(d) >= 0.0 { ng } else { -ng });
        self.query().any_hit(&Ray::new(o, d, 0.0, tmax))
    }

    /// Whether the ray along `d` that found `h` met the back of a single-sided surface: it
    /// comes from inside something (a double-sided material has no inside).
    pub fn inside(&self, h: &SurfaceHit, d: Vec3) -> bool {
        self.side(h, d) == Side::SingleBack
    }

    /// Which side of its surface the ray along `d` that found `h` met, the back told by the
    /// triangle's winding (its geometric normal) whatever the material's sidedness.
    pub fn side(&self, h: &SurfaceHit, d: Vec3) -> Side {
        if h.ng.dot(d) <= 0.0 {
            Side::Front
        } else if self.shading.materials[h.material as usize].flags & MaterialFlags::DOUBLE_SIDED == 0 {
            Side::SingleBack
        } else {
            Side::DoubleBack
        }
    }

    /// Radiance the surface `h` emits back along `d` (the ray that found it).
    fn emitted(&self, h: &SurfaceHit, d: Vec3, s: &Surface) -> Vec3 {
        if s.emission == Vec3::ZERO || self.inside(h, d) { Vec3::ZERO } else { s.emission }
    }

    /// Solid-angle density with which next-event estimation from a point `t` away picks the
    /// direction to emissive surface `h` (0 for surfaces not in the emitter table).
    pub fn emitter_pdf(&self, h: &SurfaceHit, d: Vec3) -> f32 {
        let select = self.emitters.pdf[h.triangle as usize];
        let cos = h.ng.dot(d).abs();
        if select <= 0.0 || cos <= 0.0 || h.area <= 0.0 { 0.0 } else { select * h.t * h.t / (h.area * cos) }
    }

    /// One next-event sample of the emissive triangles from `p` (leaving the side of `ng`; a
    /// free point when `ng` is zero): direction, emitted radiance (zero where occluded or facing
    /// away) and the solid-angle density of having picked that direction.
    pub fn sample_emitter(&self, p: Vec3, ng: Vec3, rng: &mut Rng) -> Option<(Vec3, Vec3, f32)> {
        let e = &self.emitters;
        if e.triangles.is_empty() {
            return None;
        }
        let u = rng.f32();
        let k = e.cdf.partition_point(|&c| c <= u).min(e.triangles.len() - 1);
        let t = e.triangles[k];
        let [a, b, c] = kiln_format::query::TriangleSource::corners(&self.tris, t as usize);
        let (r1, r2) = (rng.f32().sqrt(), rng.f32());
        let q = a * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2);
        let to = q - p;
        let dist = to.length();
        if !(dist > 0.0) {
            return None;
        }
        let d = to / dist;
        let o = if ng == Vec3::ZERO { p } else { offset(p, if ng.dot(d) >= 0.0 { ng } else { -ng }) };
        // The barycentrics of q, for the emitter's own texture coordinates.
        let hit = Hit { t: dist, triangle: t, u: r1 * (1.0 - r2), v: r1 * r2 };
        let h = self.surface_hit(d, hit);
        let s = self.shading.surface(h.material, h.uv);
        let le = self.emitted(&h, d, &s);
        let pdf = self.emitter_pdf(&h, d);
        if le == Vec3::ZERO || pdf <= 0.0 {
            return Some((d, Vec3::ZERO, pdf));
        }
        // To the sample moved off the emitter towards the origin: the emitter's own plane is not
        // in the way, however far from the world's origin both lie.
        let end = offset(q, if h.ng.dot(d) < 0.0 { h.ng } else { -h.ng });
        let to_end = end - o;
        let blocked = self.query().any_hit(&Ray::new(o, to_end.normalize_or(d), 0.0, to_end.length()));
        Some((d, if blocked { Vec3::ZERO } else { le }, pdf))
    }

    /// Radiance leaving surface `h` back along `d` (the ray that found it), without its own
    /// emission: every light's direct light and every further bounce, `bounce` events already
    /// behind the path.
    pub fn reflected(&self, h: SurfaceHit, d: Vec3, rng: &mut Rng) -> Vec3 {
        let (mut h, mut v) = (h, -d);
        let mut throughput = Vec3::ONE;
        let mut out = Vec3::ZERO;
        for bounce in 1..=MAX_BOUNCES {
            let mut s = self.shading.surface(h.material, h.uv);
            s.roughness = s.roughness.max(self.min_roughness);
            // Shade the side the ray came from.
            let (mut n, ng) = if h.ng.dot(v) < 0.0 { (-h.n, -h.ng) } else { (h.n, h.ng) };
            if n.dot(v) <= 0.0 {
                n = ng;
            }
            for light in self.shading.lights {
                // One of a rect light's stratified samples, at random, for all of them: the
                // paths average over the rest (16 shadow rays a vertex made rect-lit bakes 10×
                // slower for no less noise at the probe).
                let samples = light_samples(light, h.p);
                let pick = ((rng.f32() * samples.len() as f32) as usize).min(samples.len().saturating_sub(1));
                if let Some(&(l, e, tmax)) = samples.get(pick) {
                    let n_l = n.dot(l);
                    if n_l > 0.0 && e != Vec3::ZERO && !self.occluded(h.p, ng, l, tmax) {
                        out += throughput * self.shading.brdf(&s, n, v, l) * e * (n_l * samples.len() as f32);
                    }
                }
            }
            if let Some((l, le, pdf_light)) = self.sample_emitter(h.p, ng, rng) {
                let n_l = n.dot(l);
                if le != Vec3::ZERO && n_l > 0.0 && ng.dot(l) > 0.0 {
                    let pdf_brdf = n_l / std::f32::consts::PI;
                    let w = pdf_light / (pdf_light + pdf_brdf);
                    out += throughput * self.shading.brdf(&s, n, v, l) * le * (n_l * w / pdf_light);
                }
            }
            if bounce > ROULETTE_AFTER {
                let keep = throughput.max_element().min(0.95);
                if rng.f32() >= keep {
                    break;
                }
                throughput /= keep;
            }
            // Cosine-weighted direction around n: weight f · cos / pdf = f · π.
            let (r1, r2) = (rng.f32(), rng.f32());
            // An orthonormal basis around n (Duff et al. 2017).
            let (t1, t2) = n.any_orthonormal_pair();
            let (r, phi) = (r1.sqrt(), std::f32::consts::TAU * r2);
            let l =
                (t1 * (r * phi.cos()) + t2 * (r * phi.sin()) + n * (1.0 - r1).max(0.0).sqrt()).normalize();
            if ng.dot(l) <= 0.0 {
                break;
            }
            throughput *= self.shading.brdf(&s, n, v, l) * std::f32::consts::PI;
            if throughput.max_element() <= 0.0 {
                break;
            }
            let o = offset(h.p, ng);
            let Some(next) = self.trace(o, l, f32::INFINITY) else {
                out += throughput * self.sky.radiance(l);
                break;
            };
            let ns = self.shading.surface(next.material, next.uv);
            let le = self.emitted(&next, l, &ns);
            if le != Vec3::ZERO {
                let pdf_brdf = n.dot(l) / std::f32::consts::PI;
                let pdf_light = self.emitter_pdf(&next, l);
                out += throughput * le * (pdf_brdf / (pdf_brdf + pdf_light));
            }
            (h, v) = (next, -l);
        }
        out
    }

    /// Emitted radiance of surface `h` found along `d`.
    pub fn emission(&self, h: &SurfaceHit, d: Vec3) -> Vec3 {
        let s = self.shading.surface(h.material, h.uv);
        self.emitted(h, d, &s)
    }
}
