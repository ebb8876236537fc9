//! The file's lights and shadow maps as the direct-light pass reads them.

use kiln_format::gpu::{GpuLight, GpuShadow, LightKinds, ShadowKinds};
use kiln_format::manifest::{LightKind, Manifest, ShadowProjection};

use super::MAX_SHADOW_MAPS;
use crate::scene::ShadowImage;

/// Lights, shadow parameters and which resident map goes in which descriptor slot.
#[derive(Debug, Default)]
pub struct LightPlan {
    /// One per light (at least one element, so that the buffer is never empty).
    pub lights: Vec<GpuLight>,
    /// One per bound shadow map (at least one element).
    pub shadows: Vec<GpuShadow>,
    /// Lights to evaluate.
    pub lights_used: u32,
    /// Whether any shadow map is bound.
    pub shadows_bound: bool,
    /// Positions in the scene's resident map list bound to the 2D slots, in slot order.
    pub slots_2d: Vec<usize>,
    /// Positions bound to the cube slots, in slot order.
    pub slots_cube: Vec<usize>,
    /// Lights left unshadowed and why.
    pub warnings: Vec<String>,
}

/// Builds the plan; with `shadows` off every light is unshadowed.
pub fn plan(manifest: &Manifest, resident: &[ShadowImage], shadows: bool) -> LightPlan {
    let mut p = LightPlan::default();
    let mut shadow_of = vec![-1i32; manifest.lights.len()];
    if shadows {
        for (position, s) in resident.iter().enumerate() {
            let info = &manifest.shadow_maps[s.map];
            let cube = info.projection == ShadowProjection::Cube;
            let slots = if cube { &mut p.slots_cube } else { &mut p.slots_2d };
            if slots.len() >= MAX_SHADOW_MAPS {
                p.warnings.push(format!(
                    "light '{}' is drawn without shadows: more than {MAX_SHADOW_MAPS} {} shadow maps",
                    manifest.lights[info.light as usize].name,
                    if cube { "cube" } else { "2D" }
                ));
                continue;
            }
            let slot = slots.len() as u32;
            slots.push(position);
            shadow_of[info.light as usize] = p.shadows.len() as i32;
            p.shadows.push(GpuShadow {
                view_proj: info.view_proj,
                origin: info.origin,
                projection: match info.projection {
                    ShadowProjection::Orthographic => ShadowKinds::ORTHOGRAPHIC,
                    ShadowProjection::Perspective => ShadowKinds::PERSPECTIVE,
                    ShadowProjection::Cube => ShadowKinds::CUBE,
                },
                direction: info.direction,
                texel: info.texel,
                far: info.far,
                slot,
                resolution: info.resolution,
                reserved: 0,
            });
        }
    }
    p.shadows_bound = !p.shadows.is_empty();
    for (i, l) in manifest.lights.iter().enumerate() {
        let radiance = l.color.map(|c| c * l.intensity);
        let mut g = GpuLight {
            position: l.position,
            direction: l.direction,
            range: l.range,
            radiance,
            shadow: shadow_of[i],
            right: l.right,
            ..Default::default()
        };
        match l.kind {
            LightKind::Point => g.kind = LightKinds::POINT,
            LightKind::Spot { inner_cone, outer_cone } => {
                g.kind = LightKinds::SPOT;
                g.cos_inner = inner_cone.cos();
                g.cos_outer = outer_cone.cos();
            }
            LightKind::Directional => g.kind = LightKinds::DIRECTIONAL,
            LightKind::Rect { width, height } => {
                g.kind = LightKinds::RECT;
                g.width = width;
                g.height = height;
            }
        }
        p.lights.push(g);
    }
    p.lights_used = p.lights.len() as u32;
    if p.lights.is_empty() {
        p.lights.push(GpuLight::default());
    }
    if p.shadows.is_empty() {
        p.shadows.push(GpuShadow::default());
    }
    p
}
