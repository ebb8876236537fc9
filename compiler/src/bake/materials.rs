//! The material-table stage, and the emitted luminance of each emissive triangle where an
//! emissive texture modulates it.

use glam::{Vec2, Vec3};
use kiln_format::sections::{EMITTER_LUMINANCE, MATERIALS, NO_TEXTURE};
use rayon::prelude::*;

use super::{BakeContext, Sections};
use crate::shading::sample;

/// Sub-triangles per edge for the mean of an emissive texture: n² points, n from the texels the
/// triangle covers, at least [`MEAN_MIN`] and at most [`MEAN_MAX`].
const MEAN_MAX: u32 = 8;

/// At least 4 × 4 = 16 points whatever the texels covered: a triangle over a few texels of a
/// bilinearly filtered texture still sees its variation. (One point, what a triangle over one
/// texel got before, at the folded grid's only cell centre, lay on an edge: a triangle over a
/// two-texel white-to-black ramp weighed 0, so next-event estimation never chose it and only
/// BRDF-sampled rays found its light.)
const MEAN_MIN: u32 = 4;

/// The barycentric coordinates (weights of the second and third corners) of the centroids of
/// the n² equal sub-triangles a triangle splits into, n to an edge: equal areas, so their mean
/// of a function linear on each sub-triangle is its mean over the triangle.
fn sub_triangle_centroids(n: u32) -> impl Iterator<Item = (f32, f32)> {
    let n_f = n as f32;
    (0..n).flat_map(move |i| {
        (0..n - i).flat_map(move |j| {
            let (i, j) = (i as f32, j as f32);
            let up = ((i + 1.0 / 3.0) / n_f, (j + 1.0 / 3.0) / n_f);
            // The inverted sub-triangle beside it, where one fits.
            let down = (i + j + 2.0 <= n_f).then(|| ((i + 2.0 / 3.0) / n_f, (j + 2.0 / 3.0) / n_f));
            std::iter::once(up).chain(down)
        })
    })
}

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
/// the centroids of the triangle's n² equal sub-triangles, n from 4 to 8 as it covers more
/// texels; the factor alone where the material samples no texture; 0 for
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
                let n = (texels.sqrt().ceil() as u32).clamp(MEAN_MIN, MEAN_MAX);
                let mut sum = Vec3::ZERO;
                let mut count = 0;
                for (s, r) in sub_triangle_centroids(n) {
                    sum += sample(tex, a + (b - a) * s + (c - a) * r).truncate();
                    count += 1;
                }
                let mean = sum / count as f32;
                kiln_format::gpu::luminance((Vec3::from(mat.emission) * mean).to_array())
            })
            .collect(),
    )
}
