//! Direct-light shading as kiln defines it: what the pre-illuminated line space bakes and what
//! the player's direct-light pass computes (its GLSL mirrors these functions).
//!
//! - **Materials**: base colour = factor × texture (sRGB decoded); metalness (B) and perceptual
//!   roughness (G) = factors × texture; emission = emitted radiance × emissive texture.
//!   Normal maps are not applied at bake time.
//! - **BRDF**: `DIFFUSE_ONLY` materials are Lambertian, `base / π`. Others: Cook–Torrance with
//!   GGX (α = roughness²), Smith height-correlated visibility, Schlick Fresnel with
//!   F0 = lerp(F0_d, base, metalness) and F90 = lerp(F90_d, 1, metalness), where the dielectric's
//!   F0_d and F90_d are glTF's core 0.04 and 1 unless `KHR_materials_ior`/`specular` set them
//!   ([`GpuMaterial::dielectric`]), plus diffuse `(1 − F)(1 − metalness) base / π`; the specular
//!   lobe is scaled by `1 + F0 (1 / E − 1)` with E = R + G from the BRDF table at (n·v, roughness):
//!   multiple-scattering energy compensation (Fdez-Agüera 2019).
//! - **Lights** (units as in the sidecar): point: `I / d²`; spot: the same times
//!   smoothstep(cos outer, cos inner, cos θ); directional: irradiance `E`; rect: radiance `L`,
//!   integrated with 16 stratified samples, each weighted by both cosines over d². A light's
//!   `range` cuts it off beyond that distance. Each light (or rect sample) is occluded by a shadow
//!   ray through the BVH from the surface point, offset off the surface (Wächter and Binder).

use glam::{Vec2, Vec3, Vec4};
use kiln_format::manifest::{Light, LightKind, Wrap};
use kiln_format::query::{BvhQuery, IndexedTriangles, Ray, offset_origin};
use kiln_format::sections::{CwbvhNode, GpuMaterial, NO_TEXTURE, Vertex};

use crate::ir::{Texture, TextureRole};

/// Rect lights are integrated with this many stratified samples (4 × 4).
pub const RECT_SAMPLES: u32 = 16;

/// What shading needs of a scene (triangles in stored order).
#[derive(Debug)]
pub struct ShadingScene<'a> {
    /// Materials.
    pub materials: &'a [GpuMaterial],
    /// Textures (mip 0).
    pub textures: &'a [Texture],
    /// Lights.
    pub lights: &'a [Light],
    /// BVH nodes over `vertices`/`triangles`.
    pub bvh: &'a [CwbvhNode],
    /// Vertices.
    pub vertices: &'a [Vertex],
    /// Triangles in stored order.
    pub triangles: &'a [[u32; 3]],
    /// The BRDF table (R, G unorm16), `lut_res` × `lut_res`; empty when no material needs it.
    pub lut: &'a [[u16; 2]],
    /// Its resolution.
    pub lut_res: u32,
}

/// Linear value of an sRGB-encoded channel in [0, 1].
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Bilinear sample of mip 0 at `uv` with the texture's wrap modes; sRGB decoded for colour.
pub fn sample(t: &Texture, uv: Vec2) -> Vec4 {
    let wrap = |x: f32, w: Wrap, n: u32| -> u32 {
        let n = n as i64;
        let i = x.floor() as i64;
        let i = match w {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::ClampToEdge => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        };
        i as u32
    };
    let (x, y) = (uv.x * t.width as f32 - 0.5, uv.y * t.height as f32 - 0.5);
    let (fx, fy) = (x - x.floor(), y - y.floor());
    let texel = |dx: f32, dy: f32| {
        let (i, j) = (wrap(x + dx, t.wrap_u, t.width), wrap(y + dy, t.wrap_v, t.height));
        let o = 4 * (j as usize * t.width as usize + i as usize);
        let p = &t.rgba[o..o + 4];
        let c = |k: usize| p[k] as f32 / 255.0;
        match t.role {
            TextureRole::Color => {
                Vec4::new(srgb_to_linear(c(0)), srgb_to_linear(c(1)), srgb_to_linear(c(2)), c(3))
            }
            _ => Vec4::new(c(0), c(1), c(2), c(3)),
        }
    };
    let top = texel(0.0, 0.0).lerp(texel(1.0, 0.0), fx);
    let bottom = texel(0.0, 1.0).lerp(texel(1.0, 1.0), fx);
    top.lerp(bottom, fy)
}

/// A material's parameters at a point.
#[derive(Debug, Clone, Copy)]
pub struct Surface {
    /// Linear base colour.
    pub base: Vec3,
    /// Metalness.
    pub metallic: f32,
    /// Perceptual roughness.
    pub roughness: f32,
    /// Emitted radiance.
    pub emission: Vec3,
    /// Lambertian only.
    pub diffuse_only: bool,
    /// The dielectric part's F0 (RGB) and F90.
    pub dielectric: (Vec3, f32),
}

impl ShadingScene<'_> {
    /// The material `m` evaluated at `uv`.
    pub fn surface(&self, m: u32, uv: Vec2) -> Surface {
        let g = &self.materials[m as usize];
        let tex = |i: u32| (i != NO_TEXTURE).then(|| sample(&self.textures[i as usize], uv));
        let mut base = Vec4::from(g.base_color);
        if let Some(t) = tex(g.base_color_texture) {
            base *= t;
        }
        let (mut metallic, mut roughness) = (g.metallic, g.roughness);
        if let Some(t) = tex(g.metallic_roughness_texture) {
            metallic *= t.z;
            roughness *= t.y;
        }
        let mut emission = Vec3::from(g.emission);
        if let Some(t) = tex(g.emissive_texture) {
            emission *= t.truncate();
        }
        Surface {
            base: base.truncate(),
            metallic: metallic.clamp(0.0, 1.0),
            roughness: roughness.clamp(0.0, 1.0),
            emission,
            diffuse_only: g.diffuse_only(),
            dielectric: {
                let (f0, f90) = g.dielectric();
                (Vec3::from(f0), f90)
            },
        }
    }

    /// E = R + G of the BRDF table at (n·v, roughness), bilinear.
    pub fn directional_albedo(&self, n_v: f32, roughness: f32) -> f32 {
        if self.lut.is_empty() {
            return 1.0;
        }
        let n = self.lut_res as f32;
        let (x, y) = ((n_v * n - 0.5).clamp(0.0, n - 1.0), (roughness * n - 0.5).clamp(0.0, n - 1.0));
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(self.lut_res as usize - 1), (y0 + 1).min(self.lut_res as usize - 1));
        let e = |i: usize, j: usize| {
            let t = self.lut[j * self.lut_res as usize + i];
            (t[0] as f32 + t[1] as f32) / 65535.0
        };
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let top = e(x0, y0) + (e(x1, y0) - e(x0, y0)) * fx;
        let bottom = e(x0, y1) + (e(x1, y1) - e(x0, y1)) * fx;
        (top + (bottom - top) * fy).max(1e-3)
    }

    /// BRDF value f(l, v) (without the cosine).
    pub fn brdf(&self, s: &Surface, n: Vec3, v: Vec3, l: Vec3) -> Vec3 {
        let lambert = s.base / std::f32::consts::PI;
        if s.diffuse_only {
            return lambert;
        }
        let h = (v + l).normalize_or(n);
        let (n_v, n_l, n_h, v_h) =
            (n.dot(v).max(1e-4), n.dot(l).max(1e-4), n.dot(h).max(0.0), v.dot(h).max(0.0));
        let alpha = (s.roughness * s.roughness).max(1e-3);
        let a2 = alpha * alpha;
        let d = a2 / (std::f32::consts::PI * (n_h * n_h * (a2 - 1.0) + 1.0).powi(2));
        let vis =
            0.5 / (n_l * (n_v * n_v * (1.0 - a2) + a2).sqrt() + n_v * (n_l * n_l * (1.0 - a2) + a2).sqrt());
        let f0 = s.dielectric.0.lerp(s.base, s.metallic);
        let f90 = Vec3::splat(s.dielectric.1 + (1.0 - s.dielectric.1) * s.metallic);
        let f = f0 + (f90 - f0) * (1.0 - v_h).powi(5);
        let compensation = Vec3::ONE + f0 * (1.0 / self.directional_albedo(n_v, s.roughness) - 1.0);
        let specular = f * (d * vis) * compensation;
        (Vec3::ONE - f) * (1.0 - s.metallic) * lambert + specular
    }

    /// Whether the segment from `p` (on a surface of geometric normal `ng`, facing the ray) to
    /// `p + d·tmax` is blocked.
    pub fn occluded(&self, p: Vec3, ng: Vec3, d: Vec3, tmax: f32) -> bool {
        let tris = IndexedTriangles { vertices: self.vertices, triangles: self.triangles };
        let o = offset_origin(p, if ng.dot(d) >= 0.0 { ng } else { -ng });
        BvhQuery::new(self.bvh, &tris).any_hit(&Ray::new(o, d, 0.0, tmax))
    }

    /// Outgoing radiance towards `v` at point `p` with shading normal `n` and geometric normal
    /// `ng`: emission plus every light's direct contribution, shadowed.
    pub fn radiance(&self, p: Vec3, n: Vec3, ng: Vec3, v: Vec3, material: u32, uv: Vec2) -> Vec3 {
        let s = self.surface(material, uv);
        // Shade the side the viewer is on.
        let (n, ng) = if ng.dot(v) < 0.0 { (-n, -ng) } else { (n, ng) };
        let n = if n.dot(v) <= 0.0 { ng } else { n };
        let mut out = s.emission;
        for light in self.lights {
            for (l, e, tmax) in light_samples(light, p) {
                let n_l = n.dot(l);
                if n_l <= 0.0 || e == Vec3::ZERO || self.occluded(p, ng, l, tmax) {
                    continue;
                }
                out += self.brdf(&s, n, v, l) * e * n_l;
            }
        }
        out
    }
}

/// The light arriving at `p` from `light`: (unit direction to the light, irradiance on a
/// surface facing it, shadow-ray length) per sample.
pub fn light_samples(light: &Light, p: Vec3) -> Vec<(Vec3, Vec3, f32)> {
    let color = Vec3::from(light.color) * light.intensity;
    let pos = Vec3::from(light.position);
    let dir = Vec3::from(light.direction).normalize_or(Vec3::NEG_Y);
    let in_range = |d: f32| light.range <= 0.0 || d <= light.range;
    match light.kind {
        LightKind::Directional => vec![(-dir, color, f32::INFINITY)],
        LightKind::Point | LightKind::Spot { .. } => {
            let to = pos - p;
            let d = to.length();
            if d <= 0.0 || !in_range(d) {
                return vec![];
            }
            let l = to / d;
            let cone = match light.kind {
                LightKind::Spot { inner_cone, outer_cone } => {
                    let (co, ci) = (outer_cone.cos(), inner_cone.cos());
                    let c = (-l).dot(dir);
                    let t = ((c - co) / (ci - co).max(1e-6)).clamp(0.0, 1.0);
                    t * t * (3.0 - 2.0 * t)
                }
                _ => 1.0,
            };
            vec![(l, color * cone / (d * d), d * (1.0 - 1e-5))]
        }
        LightKind::Rect { width, height } => {
            let right = Vec3::from(light.right).normalize_or(Vec3::X);
            let up = dir.cross(right);
            let k = (RECT_SAMPLES as f32).sqrt() as u32;
            let area = width * height;
            let mut out = Vec::with_capacity(RECT_SAMPLES as usize);
            for i in 0..k {
                for j in 0..k {
                    let (u, v) = ((i as f32 + 0.5) / k as f32 - 0.5, (j as f32 + 0.5) / k as f32 - 0.5);
                    let q = pos + right * (u * width) + up * (v * height);
                    let to = q - p;
                    let d = to.length();
                    if d <= 0.0 || !in_range(d) {
                        continue;
                    }
                    let l = to / d;
                    let cos_light = (-l).dot(dir);
                    if cos_light <= 0.0 {
                        continue;
                    }
                    out.push((
                        l,
                        color * (cos_light * area / (RECT_SAMPLES as f32 * d * d)),
                        d * (1.0 - 1e-5),
                    ));
                }
            }
            out
        }
    }
}
