//! Scene validation after import and sidecar: drops degenerate triangles, refuses empty
//! scenes, fills defaults that depend on the whole scene (camera, media bounds).

use glam::{DVec3, Vec3};
use kiln_format::manifest::{Bounds, Camera};

use crate::exit::{CliError, CliResult};
use crate::ir::{Scene, WarningClass};

/// Whether a triangle has zero area: repeated indices, or corners that are collinear in
/// double precision.
pub fn is_degenerate(scene: &Scene, t: [u32; 3]) -> bool {
    if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
        return true;
    }
    let p = |i: u32| DVec3::from(scene.vertices[i as usize].position.map(f64::from));
    let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
    (b - a).cross(c - a) == DVec3::ZERO
}

/// Bounds of all vertices referenced by triangles.
pub fn bounds(scene: &Scene) -> Bounds {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for t in &scene.triangles {
        for &i in t {
            let p = Vec3::from(scene.vertices[i as usize].position);
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    Bounds { min: lo.to_array(), max: hi.to_array() }
}

/// Validates and completes `scene`; `source` names the input in messages.
pub fn finish(scene: &mut Scene, source: &str) -> CliResult<()> {
    let before = scene.triangles.len();
    let keep: Vec<bool> = scene.triangles.iter().map(|&t| !is_degenerate(scene, t)).collect();
    let mut k = keep.iter();
    scene.triangles.retain(|_| *k.next().unwrap_or(&true));
    let mut k = keep.iter();
    scene.triangle_materials.retain(|_| *k.next().unwrap_or(&true));
    let dropped = (before - scene.triangles.len()) as u64;
    scene.degenerate_triangles += dropped;
    if dropped > 0 {
        scene.warn(format!("{source}: {dropped} degenerate (zero-area) triangles dropped"));
    }
    if scene.triangles.is_empty() {
        return Err(CliError::input(format!(
            "{source}: the scene has no triangles{}",
            if before > 0 { " (all were degenerate)" } else { "" }
        )));
    }
    if !scene.uses_textures() {
        scene.uvs.clear();
    }
    settle_opaque_blends(scene);
    let b = bounds(scene);
    let (lo, hi) = (Vec3::from(b.min), Vec3::from(b.max));
    let diagonal = (hi - lo).length().max(f32::MIN_POSITIVE);
    for m in &mut scene.media {
        if m.bounds.min[0].is_nan() {
            m.bounds = b;
        }
        let non_empty = (0..3).all(|a| m.bounds.min[a] < m.bounds.max[a]);
        if !non_empty {
            return Err(CliError::input(format!(
                "{source}: medium box {:?}..{:?} is empty",
                m.bounds.min, m.bounds.max
            )));
        }
    }
    if scene.cameras.is_empty() {
        // Look at the scene from +z, far enough for a 45° field of view to hold it.
        let centre = (lo + hi) * 0.5;
        let distance = diagonal * 0.5 / (22.5f32.to_radians().tan()) + (hi.z - lo.z) * 0.5;
        scene.cameras.push(Camera {
            name: "default".into(),
            position: (centre + Vec3::Z * distance).to_array(),
            target: centre.to_array(),
            up: [0.0, 1.0, 0.0],
            vfov_degrees: 45.0,
            znear: 0.0,
            zfar: 0.0,
        });
        scene.warn_as(
            WarningClass::MissingSetup,
            format!(
                "{source}: no camera in the asset or sidecar; a default camera framing the scene was added"
            ),
        );
    }
    for c in &mut scene.cameras {
        if c.znear <= 0.0 {
            c.znear = diagonal * 1e-4;
        }
    }
    if !scene.lit() {
        scene.warn_as(WarningClass::MissingSetup, format!("{source}: the scene has no lights, no emissive materials and a black sky; it will render black (add lights in a sidecar, or light it with --environment studio, a neutral built-in environment)"));
    }
    Ok(())
}

/// Alpha-blended (glTF BLEND) materials whose alpha is 1 everywhere — the factor, every texel of
/// the base colour texture and the vertex colours of their triangles — are made opaque. They look
/// the same (the path tracer meets such a surface with probability 1), and the player's
/// see-through layer, which lights less than the G-buffer does, is kept for the surfaces that need
/// it: exporters often mark whole models BLEND.
fn settle_opaque_blends(scene: &mut Scene) {
    use kiln_format::sections::{AlphaMode, MaterialFlags, NO_TEXTURE};
    let mut translucent_colors = vec![false; scene.materials.len()];
    if !scene.colors.is_empty() {
        for (t, &m) in scene.triangles.iter().zip(&scene.triangle_materials) {
            if t.iter().any(|&v| scene.colors.get(v as usize).is_some_and(|c| c[3] < u16::MAX))
                && let Some(x) = translucent_colors.get_mut(m as usize)
            {
                *x = true;
            }
        }
    }
    let textures = &scene.textures;
    for (m, translucent) in scene.materials.iter_mut().zip(translucent_colors) {
        let g = &mut m.gpu;
        if g.alpha_mode() != Some(AlphaMode::Blend) || !(g.base_color[3] >= 1.0) || translucent {
            continue;
        }
        let texture_opaque = g.base_color_texture == NO_TEXTURE
            || textures
                .get(g.base_color_texture as usize)
                .is_some_and(|t| t.rgba.chunks_exact(4).all(|p| p[3] == u8::MAX));
        if texture_opaque {
            g.flags &= !MaterialFlags::ALPHA_MODE_MASK;
        }
    }
}
