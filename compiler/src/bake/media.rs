//! The light-visibility volume of a participating medium: over the medium's box, nearly cubic
//! cells (box / dims per axis) holding, per light, the fraction of shadow rays from points in the
//! cell that reach the light; and, where a sky lights the scene (an environment or a constant
//! sky), three grids of the sky's light reaching each cell (format 1.10, [`sky_grids`]).
//! A player ray-marching single scattering looks visibility up here instead of in a screen-space
//! image, so shafts stay right when the light is off screen or behind geometry (seed 002's main
//! failure cases).

use glam::Vec3;
use kiln_format::manifest::{Light, LightKind, MediaVisibilityInfo, Medium};
use rayon::prelude::*;

use crate::shading::ShadingScene;

/// Shadow rays per cell and light (points on a 2 × 2 × 2 stratified pattern with per-cell
/// jitter; rect lights are sampled at matching strata).
pub const SAMPLES: u32 = 8;

/// Cells of the volume over `m` with `res` cells along its longest axis.
pub fn dims(m: &Medium, res: u32) -> [u32; 3] {
    let ext = Vec3::from(m.bounds.max) - Vec3::from(m.bounds.min);
    let cell = ext.max_element() / res as f32;
    [0, 1, 2].map(|a| ((ext[a] / cell).ceil() as u32).clamp(1, res))
}

/// The cell (x, y, z) of linear index `i` (x fastest).
fn cell_of(i: usize, dims: [u32; 3]) -> [u32; 3] {
    let (w, h) = (dims[0] as usize, dims[1] as usize);
    [(i % w) as u32, ((i / w) % h) as u32, (i / (w * h)) as u32]
}

/// The k-th sample point of cell `c` (stratified, jittered by a hash of the cell).
pub fn sample_point(m: &Medium, dims: [u32; 3], c: [u32; 3], k: u32) -> Vec3 {
    let lo = Vec3::from(m.bounds.min);
    let size = (Vec3::from(m.bounds.max) - lo) / Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32);
    let h = (c[0].wrapping_mul(73_856_093) ^ c[1].wrapping_mul(19_349_663) ^ c[2].wrapping_mul(83_492_791))
        .wrapping_add(k.wrapping_mul(2_654_435_761));
    let jitter =
        |s: u32| ((h.rotate_left(s).wrapping_mul(0x9e37_79b9) >> 8) as f32 / (1u32 << 24) as f32) * 0.5;
    let strata = Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32) * 0.5;
    let f = strata + Vec3::new(jitter(0), jitter(11), jitter(22));
    lo + (Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) + f) * size
}

/// Whether light `l` is visible from `p` for sample `k` (rect lights: at the k-th stratum).
pub fn visible(scene: &ShadingScene, light: &Light, p: Vec3, k: u32) -> bool {
    let (target, infinite) = match light.kind {
        LightKind::Directional => (p - Vec3::from(light.direction).normalize_or(Vec3::NEG_Y), true),
        LightKind::Rect { width, height } => {
            let right = Vec3::from(light.right).normalize_or(Vec3::X);
            let up = Vec3::from(light.direction).cross(right);
            let (u, v) = (((k % 4) as f32 + 0.5) / 4.0 - 0.5, ((k / 4 % 4) as f32 + 0.5) / 4.0 - 0.5);
            (Vec3::from(light.position) + right * (u * width) + up * (v * height), false)
        }
        _ => (Vec3::from(light.position), false),
    };
    let d = target - p;
    let len = d.length();
    if len == 0.0 {
        return true;
    }
    let tmax = if infinite { f32::INFINITY } else { len * (1.0 - 1e-5) };
    let tris = kiln_format::query::IndexedTriangles { vertices: scene.vertices, triangles: scene.triangles };
    !kiln_format::query::BvhQuery::new(scene.bvh, &tris).any_hit(&kiln_format::query::Ray::new(
        p,
        d / len,
        0.0,
        tmax,
    ))
}

/// Bakes the volume of medium `index` for every shadow-casting light: (record, one u8 grid per
/// listed light, x fastest).
pub fn bake(
    scene: &ShadingScene,
    media: &[Medium],
    index: u32,
    res: u32,
) -> (MediaVisibilityInfo, Vec<Vec<u8>>) {
    let m = &media[index as usize];
    let dims = dims(m, res);
    let lights: Vec<u32> =
        scene.lights.iter().enumerate().filter(|(_, l)| l.casts_shadows).map(|(i, _)| i as u32).collect();
    let cells = (dims[0] * dims[1] * dims[2]) as usize;
    let volumes = lights
        .iter()
        .map(|&li| {
            let light = &scene.lights[li as usize];
            (0..cells)
                .into_par_iter()
                .map(|i| {
                    let c = cell_of(i, dims);
                    let seen = (0..SAMPLES)
                        .filter(|&k| visible(scene, light, sample_point(m, dims, c, k), k))
                        .count();
                    (seen as f32 / SAMPLES as f32 * 255.0).round() as u8
                })
                .collect()
        })
        .collect();
    (MediaVisibilityInfo { medium: index, dims, samples: SAMPLES, lights }, volumes)
}

/// Directions per cell for the sky's grids: 8 bands of equal solid angle in cos θ by 4 in φ,
/// jittered per cell.
pub const SKY_SAMPLES: u32 = 32;

/// Two numbers in [0, 1) from cell `cell` and sample `k` (a PCG-style hash: independent across
/// cells and samples, the same on every machine).
fn jitter(cell: u32, k: u32) -> [f32; 2] {
    let mut h = cell.wrapping_mul(0x9e37_79b9) ^ k.wrapping_mul(0x85eb_ca6b).rotate_left(13);
    let mut next = || {
        h = h.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        let w = ((h >> ((h >> 28) + 4)) ^ h).wrapping_mul(277_803_737);
        ((w >> 22) ^ w) >> 8
    };
    let a = next();
    let b = next();
    [a as f32 / (1u32 << 24) as f32, b as f32 / (1u32 << 24) as f32]
}

/// The sky's radiance luminance towards unit direction `d`: the environment's texel (nearest,
/// turned by its rotation) or the constant sky's.
fn sky_luminance(scene: &crate::ir::Scene, d: Vec3) -> f32 {
    let Some(env) = &scene.environment else {
        return kiln_format::gpu::luminance(scene.sky.radiance);
    };
    // The map is turned by +rotation about y: the texel seen along d is the source's along d
    // turned back.
    let local = glam::Quat::from_rotation_y(-env.rotation_degrees.to_radians()) * d;
    kiln_format::gpu::luminance(env.pixels[kiln_format::environment::texel_of(local, env.width, env.height)])
}

/// The sky's three grids over medium `m` (R, G, B, x fastest): per cell, the sky's light that
/// reaches it through the geometry and through the medium itself, relative to the sky's whole:
/// Σ_k w_k V_k e^{−σt,c·d_k} / Σ_k w_k over [`SKY_SAMPLES`] directions of equal solid angle from
/// points of the cell, w_k the sky's luminance along direction k, V_k whether the ray escapes the
/// geometry, d_k its length inside the medium's box. Lit by the sky's radiance L and its phase
/// function, the cell scatters σs · (that) · ∫ p L dω / ∫ L dω-weighted (exact for a uniform sky
/// and any phase function; the player convolves the sky with the phase function).
pub fn sky_grids(
    scene: &crate::ir::Scene,
    shading: &ShadingScene,
    m: &Medium,
    dims: [u32; 3],
) -> [Vec<u8>; 3] {
    let cells = (dims[0] * dims[1] * dims[2]) as usize;
    let sigma_t = Vec3::from(m.sigma_a) + Vec3::from(m.sigma_s);
    let (lo, hi) = (Vec3::from(m.bounds.min), Vec3::from(m.bounds.max));
    let tris =
        kiln_format::query::IndexedTriangles { vertices: shading.vertices, triangles: shading.triangles };
    let values: Vec<[u8; 3]> = (0..cells)
        .into_par_iter()
        .map(|i| {
            let c = cell_of(i, dims);
            let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
            for k in 0..SKY_SAMPLES {
                let p = sample_point(m, dims, c, k % SAMPLES);
                // A direction in band k / 4 of cos θ and k % 4 of φ, jittered within them by a
                // hash of the cell and k.
                let [jc, jp] = jitter(i as u32, k);
                let cos = 1.0 - 2.0 * (((k / 4) as f32 + jc) / (SKY_SAMPLES / 4) as f32);
                let phi = std::f32::consts::TAU * (((k % 4) as f32 + jp) / 4.0);
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                let d = Vec3::new(sin * phi.cos(), cos, sin * phi.sin());
                let w = sky_luminance(scene, d);
                weight += w;
                if w <= 0.0 {
                    continue;
                }
                let ray = kiln_format::query::Ray::new(p, d, 0.0, f32::INFINITY);
                if kiln_format::query::BvhQuery::new(shading.bvh, &tris).any_hit(&ray) {
                    continue;
                }
                // Length inside the box from p (inside it) along d.
                let t = [0, 1, 2]
                    .map(|a| {
                        if d[a] > 0.0 {
                            (hi[a] - p[a]) / d[a]
                        } else if d[a] < 0.0 {
                            (lo[a] - p[a]) / d[a]
                        } else {
                            f32::INFINITY
                        }
                    })
                    .into_iter()
                    .fold(f32::INFINITY, f32::min)
                    .max(0.0);
                sum += w * (-sigma_t * t).exp();
            }
            let v = if weight > 0.0 { sum / weight } else { Vec3::ZERO };
            v.to_array().map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
        })
        .collect();
    [0, 1, 2].map(|ch| values.iter().map(|v| v[ch]).collect())
}

/// The light-visibility stage: the volume of medium 0, one grid per shadow-casting light, then
/// the sky's three where a sky lights the scene.
pub fn stage(ctx: &super::BakeContext) -> super::Sections {
    let res = ctx.settings.media_volume_res;
    let shading = ctx.shading();
    let (mut info, mut volumes) = bake(&shading, &ctx.scene.media, 0, res);
    if ctx.scene.sky_lights()
        && let Some(m) = ctx.scene.media.first()
    {
        volumes.extend(sky_grids(ctx.scene, &shading, m, info.dims));
        info.lights.extend(MediaVisibilityInfo::SKY);
    }
    let mut out = super::Sections::default();
    for (i, v) in volumes.into_iter().enumerate() {
        out.push(kiln_format::sections::MEDIA_VISIBILITY, i as u32, v);
    }
    out.media_visibility = Some(info);
    out
}
