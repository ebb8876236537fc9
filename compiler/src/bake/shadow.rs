//! Shadow maps, made exactly: every texel's depth is the first hit of the ray through its
//! centre, cast through the baked BVH (the same traversal `kiln verify` holds to brute force).
//!
//! Projections (the choice per light kind):
//! - directional: orthographic along the light direction, fitted to the scene bounds;
//! - spot: perspective from the light position along its axis, field of view twice the outer
//!   cone (at most 170°);
//! - point: a cube map around the light position;
//! - rect: a cube map around the rectangle's centre. Rays from the whole rectangle cannot be
//!   represented in one depth map; the player treats the rect light as a point at its centre for
//!   the occluder search (PCSS) and takes the penumbra width from the rectangle's size. Only the
//!   faces towards the emitting side matter, but all six are stored so that one sampler serves
//!   point and rect lights alike.
//!
//! Depth is the distance along the texel's unit ray: from the near plane for orthographic maps,
//! from the light position otherwise. Texels whose ray hits nothing hold `f32::MAX`.

use glam::{DMat4, DVec3, Mat4, Vec3};
use kiln_format::manifest::{Bounds, Light, LightKind, ShadowMapInfo, ShadowProjection};
use kiln_format::projection::{look_to_rh, orthographic_rh, perspective_rh};
use kiln_format::query::{BvhQuery, Ray, TriangleSource};
use kiln_format::sections::CwbvhNode;
use rayon::prelude::*;

/// Depth of texels whose ray hits nothing.
pub const NO_OCCLUDER: f32 = f32::MAX;

/// Direction through texel (x, y) of cube face `face` (Vulkan face order +X −X +Y −Y +Z −Z and
/// orientation: u = (s_c / |m_a| + 1) / 2 and v = (t_c / |m_a| + 1) / 2 with v down the image).
pub fn cube_direction(face: u32, x: u32, y: u32, n: u32) -> Vec3 {
    let sc = 2.0 * (x as f32 + 0.5) / n as f32 - 1.0;
    let tc = 2.0 * (y as f32 + 0.5) / n as f32 - 1.0;
    let d = match face {
        0 => Vec3::new(1.0, -tc, -sc),
        1 => Vec3::new(-1.0, -tc, sc),
        2 => Vec3::new(sc, 1.0, tc),
        3 => Vec3::new(sc, -1.0, -tc),
        4 => Vec3::new(sc, -tc, 1.0),
        _ => Vec3::new(-sc, -tc, -1.0),
    };
    d.normalize()
}

/// A vector perpendicular to `d` (unit).
fn perpendicular(d: Vec3) -> Vec3 {
    let a = if d.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    d.cross(a).normalize()
}

fn corners(b: &Bounds) -> [Vec3; 8] {
    let (lo, hi) = (Vec3::from(b.min), Vec3::from(b.max));
    std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// How a map's texel rays are laid out.
#[derive(Debug, Clone)]
pub struct Layout {
    /// Manifest record.
    pub info: ShadowMapInfo,
    /// Clip → world for 2D maps (for texel rays): the stored (f32) matrix inverted in f64, once
    /// per map rather than per texel.
    clip_to_world: DMat4,
}

/// The map layout of `light` (number `index`) over `bounds`, or `None` if it casts no shadows.
pub fn layout(light: &Light, index: u32, bounds: &Bounds, res: u32) -> Option<Layout> {
    if !light.casts_shadows {
        return None;
    }
    let pts = corners(bounds);
    let diag = (Vec3::from(bounds.max) - Vec3::from(bounds.min)).length().max(1e-6);
    let pos = Vec3::from(light.position);
    let dir = Vec3::from(light.direction).normalize_or(Vec3::NEG_Y);
    let far_from = |p: Vec3| pts.iter().map(|c| (*c - p).length()).fold(0.0f32, f32::max).max(diag * 1e-3);
    let (projection, view_proj, origin, near, far, texel, resolution) = match light.kind {
        LightKind::Directional => {
            let right = perpendicular(dir);
            let up = right.cross(dir);
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for c in pts {
                let q = Vec3::new(c.dot(right), c.dot(up), c.dot(dir));
                lo = lo.min(q);
                hi = hi.max(q);
            }
            let pad = diag * 0.01;
            let (lo, hi) = (lo - pad, hi + pad);
            let centre = right * (lo.x + hi.x) * 0.5 + up * (lo.y + hi.y) * 0.5 + dir * lo.z;
            let view = look_to_rh(centre.as_dvec3(), dir.as_dvec3(), up.as_dvec3());
            let (w, h) = (hi.x - lo.x, hi.y - lo.y);
            let proj = orthographic_rh(
                -w as f64 * 0.5,
                w as f64 * 0.5,
                -h as f64 * 0.5,
                h as f64 * 0.5,
                0.0,
                (hi.z - lo.z) as f64,
            );
            (
                ShadowProjection::Orthographic,
                (proj * view).as_mat4(),
                centre,
                0.0,
                hi.z - lo.z,
                w.max(h) / res as f32,
                res,
            )
        }
        LightKind::Spot { outer_cone, .. } => {
            let fov = (2.0 * outer_cone).clamp(1e-3, 170f32.to_radians());
            let near = diag * 1e-4;
            let far = far_from(pos);
            let view = look_to_rh(pos.as_dvec3(), dir.as_dvec3(), perpendicular(dir).as_dvec3());
            let proj = perspective_rh(fov as f64, 1.0, near as f64, far as f64);
            (ShadowProjection::Perspective, (proj * view).as_mat4(), pos, near, far, fov / res as f32, res)
        }
        LightKind::Point | LightKind::Rect { .. } => {
            let n = (res / 2).max(1);
            (
                ShadowProjection::Cube,
                Mat4::IDENTITY,
                pos,
                0.0,
                far_from(pos),
                std::f32::consts::FRAC_PI_2 / n as f32,
                n,
            )
        }
    };
    Some(Layout {
        info: ShadowMapInfo {
            light: index,
            projection,
            resolution,
            view_proj: view_proj.to_cols_array(),
            origin: origin.to_array(),
            direction: dir.to_array(),
            near,
            far,
            texel,
        },
        clip_to_world: DMat4::from_cols_array(&view_proj.to_cols_array().map(f64::from)).inverse(),
    })
}

impl Layout {
    /// Number of depth values: N² or 6 N².
    pub fn len(&self) -> usize {
        let n = self.info.resolution as usize;
        n * n * if self.info.projection == ShadowProjection::Cube { 6 } else { 1 }
    }

    /// Whether the map is empty (never: N ≥ 1).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The ray of texel `k` (faces, then rows top to bottom, then columns).
    pub fn texel_ray(&self, k: usize) -> Ray {
        let n = self.info.resolution as usize;
        let (face, rest) = (k / (n * n), k % (n * n));
        let (x, y) = ((rest % n) as u32, (rest / n) as u32);
        let origin = Vec3::from(self.info.origin);
        match self.info.projection {
            ShadowProjection::Cube => {
                Ray::new(origin, cube_direction(face as u32, x, y, n as u32), 0.0, f32::INFINITY)
            }
            ShadowProjection::Orthographic | ShadowProjection::Perspective => {
                // Through the texel centre of the stored (f32) matrix, unprojected in f64: a
                // perspective map's far/near ratio (~10⁴) makes the f32 inverse stray by a
                // tenth of a texel, and the map would not be what its matrix says.
                let ndc_x = 2.0 * (x as f64 + 0.5) / n as f64 - 1.0;
                let ndc_y = 1.0 - 2.0 * (y as f64 + 0.5) / n as f64;
                let inv = self.clip_to_world;
                let near = inv.project_point3(DVec3::new(ndc_x, ndc_y, 0.0));
                let far = inv.project_point3(DVec3::new(ndc_x, ndc_y, 1.0));
                let d = (far - near).normalize_or(DVec3::from(self.info.direction.map(f64::from))).as_vec3();
                if self.info.projection == ShadowProjection::Orthographic {
                    Ray::new(near.as_vec3(), d, 0.0, f32::INFINITY)
                } else {
                    Ray::new(origin, d, 0.0, f32::INFINITY)
                }
            }
        }
    }
}

/// Renders the map: one BVH ray per texel.
pub fn render(layout: &Layout, bvh: &[CwbvhNode], tris: &(impl TriangleSource + ?Sized)) -> Vec<f32> {
    render_counted(layout, bvh, tris, &crate::progress::Progress::hidden())
}

/// [`render`], counting texels on `progress` a row at a time.
pub fn render_counted(
    layout: &Layout,
    bvh: &[CwbvhNode],
    tris: &(impl TriangleSource + ?Sized),
    progress: &crate::progress::Progress,
) -> Vec<f32> {
    let q = BvhQuery::new(bvh, tris);
    let row = layout.info.resolution as usize;
    (0..layout.len())
        .into_par_iter()
        .map(|k| {
            if k % row == row - 1 {
                progress.inc(row as u64);
            }
            q.closest_hit(&layout.texel_ray(k)).map_or(NO_OCCLUDER, |h| h.t)
        })
        .collect()
}

/// The shadow-map stage: one map (or cube map) per shadow-casting light, rendered through the
/// BVH; section indices count the maps, the records name their lights.
pub fn stage(ctx: &super::BakeContext) -> super::Sections {
    let res = ctx.settings.shadow_res;
    let triangles = ctx.indexed();
    let mut out = super::Sections::default();
    let layouts: Vec<Layout> = ctx
        .scene
        .lights
        .iter()
        .enumerate()
        .filter_map(|(i, light)| layout(light, i as u32, &ctx.geometry.bounds, res))
        .collect();
    ctx.progress.count("shadow maps: texels", layouts.iter().map(|l| l.len() as u64).sum());
    for layout in layouts {
        let depths = render_counted(&layout, &ctx.bvh.nodes, &triangles, ctx.progress);
        out.push(
            kiln_format::sections::SHADOW_MAP,
            out.shadow_maps.len() as u32,
            bytemuck::cast_slice(&depths).to_vec(),
        );
        out.shadow_maps.push(layout.info);
    }
    out
}
