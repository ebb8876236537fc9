//! The material-table stage, and the emitted luminance of each emissive triangle where an
//! emissive texture modulates it.

use glam::{Vec2, Vec3};
use kiln_format::sections::{EMITTER_LUMINANCE, MATERIALS, NO_TEXTURE};
use rayon::prelude::*;

use super::{BakeContext, Sections};
use crate::shading::sample;

/// Stratified points per triangle edge for the mean of an emissive texture (up to 8 × 8 = 64
/// points, fewer where the triangle covers fewer texels).
const MEAN_STRATA: u32 = 8;

/// The GPU material table; with an emissive texture anywhere, each triangle's mean emitted
/// luminance too.
pub fn stage(ctx: &BakeContext) -> Sections {
    let mut out = Sections::default();
    out.push(MATERIALS, 0, bytemuck::cast_slice(&ctx.materials).to_vec());
    if let Some(l) = emitted_luminance(ctx) {
        out.push(EMITTER_LUMINANCE, 0, bytemuck::cast_slice(&l).to_vec());
    }
    out
}

/// Whether some material both emits and samples an emissive texture (then the emitter tables
/// weigh triangles by what their texture lets out, not by the factor alone).
pub fn textured_emission(ctx: &BakeContext) -> bool {
    ctx.materials.iter().any(|m| {
        m.emissive_texture != NO_TEXTURE
            && kiln_format::gpu::luminance(m.emission) > 0.0
            && !ctx.scene.uvs.is_empty()
    })
}

/// Per stored triangle, the luminance of its emitted radiance (emission factor × emissive
/// texture) averaged over the triangle: the texture bilinearly sampled (mip 0, sRGB decoded) at
/// the centres of a stratified barycentric grid of up to 8 × 8 cells, fewer where the triangle
/// covers fewer texels; the factor alone where the material samples no texture; 0 for
/// triangles that do not emit. `None` where no material has an emissive texture.
pub fn emitted_luminance(ctx: &BakeContext) -> Option<Vec<f32>> {
    if !textured_emission(ctx) {
        return None;
    }
    let scene = ctx.scene;
    let uv = |v: u32| Vec2::from(scene.uvs[v as usize]);
    Some(
        ctx.triangles
            .par_iter()
            .zip(&ctx.triangle_materials)
            .map(|(t, &m)| {
                let mat = &ctx.materials[m as usize];
                let factor = kiln_format::gpu::luminance(mat.emission);
                if factor <= 0.0 || mat.emissive_texture == NO_TEXTURE {
                    return factor.max(0.0);
                }
                let tex = &scene.textures[mat.emissive_texture as usize];
                let [a, b, c] = t.map(uv);
                let texels = 0.5 * ((b - a).perp_dot(c - a)).abs() * tex.width as f32 * tex.height as f32;
                let n = (texels.sqrt().ceil() as u32).clamp(1, MEAN_STRATA);
                let mut sum = Vec3::ZERO;
                let mut count = 0;
                // Cell (i, j) of the n × n grid over the unit square, folded onto the triangle.
                for i in 0..n {
                    for j in 0..n {
                        let (mut s, mut r) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                        if s + r > 1.0 {
                            (s, r) = (1.0 - s, 1.0 - r);
                        }
                        sum += sample(tex, a + (b - a) * s + (c - a) * r).truncate();
                        count += 1;
                    }
                }
                let mean = sum / count as f32;
                kiln_format::gpu::luminance((Vec3::from(mat.emission) * mean).to_array())
            })
            .collect(),
    )
}
