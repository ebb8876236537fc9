//! The light-visibility volume of a participating medium: over the medium's box, nearly cubic
//! cells (box / dims per axis) holding, per light, the fraction of shadow rays from points in the
//! cell that reach the light.
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
                    let c = [
                        (i % dims[0] as usize) as u32,
                        ((i / dims[0] as usize) % dims[1] as usize) as u32,
                        (i / (dims[0] * dims[1]) as usize) as u32,
                    ];
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

/// The light-visibility stage: the volume of medium 0, one grid per shadow-casting light.
pub fn stage(ctx: &super::BakeContext) -> super::Sections {
    let res = ctx.settings.media_volume_res;
    let (info, volumes) = bake(&ctx.shading(), &ctx.scene.media, 0, res);
    let mut out = super::Sections::default();
    for (i, v) in volumes.into_iter().enumerate() {
        out.push(kiln_format::sections::MEDIA_VISIBILITY, i as u32, v);
    }
    out.media_visibility = Some(info);
    out
}
