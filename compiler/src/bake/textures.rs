//! The texture stage: full mip chains, filtered in linear space, then stored as RGBA8 or
//! block-compressed level by level ([`super::bc`]).
//!
//! Each level halves the previous one (rounding down, at least 1) with a 2×2 box filter, edge
//! texels clamped for odd sizes. sRGB colour is filtered after conversion to linear light and
//! converted back; normal maps are averaged as vectors and renormalised; other data is averaged
//! as is. Alpha is always linear.

use rayon::prelude::*;

use kiln_format::sections::{PixelFormat, encode_texture};

use super::bc::{self, Choice, FLIP_BOUND, PSNR_BOUND_DB, TextureReport, Usage, choose};
use crate::ir::{Texture, TextureRole};

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

fn linear_to_srgb(l: f32) -> u8 {
    let l = l.clamp(0.0, 1.0);
    let c = if l <= 0.003_130_8 { l * 12.92 } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 };
    (c * 255.0 + 0.5) as u8
}

/// Texels of one level, as floats in the role's filtering space.
struct Level {
    width: u32,
    height: u32,
    texels: Vec<[f32; 4]>,
}

/// The whole mip chain of `t` as RGBA8, level 0 first.
pub fn mip_chain(t: &Texture) -> Vec<u8> {
    let levels = kiln_format::scene::mip_levels(t.width, t.height);
    let mut out = Vec::with_capacity(t.rgba.len() * 4 / 3 + 4);
    out.extend_from_slice(&t.rgba);
    let lut: Vec<f32> = (0..=255u8).map(srgb_to_linear).collect();
    let decode = |px: &[u8]| -> [f32; 4] {
        let a = px[3] as f32 / 255.0;
        match t.role {
            TextureRole::Color => [lut[px[0] as usize], lut[px[1] as usize], lut[px[2] as usize], a],
            TextureRole::Data => [px[0] as f32 / 255.0, px[1] as f32 / 255.0, px[2] as f32 / 255.0, a],
            TextureRole::Normal => {
                [px[0] as f32 / 127.5 - 1.0, px[1] as f32 / 127.5 - 1.0, px[2] as f32 / 127.5 - 1.0, a]
            }
        }
    };
    let encode = |v: [f32; 4]| -> [u8; 4] {
        let unorm = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        match t.role {
            TextureRole::Color => {
                [linear_to_srgb(v[0]), linear_to_srgb(v[1]), linear_to_srgb(v[2]), unorm(v[3])]
            }
            TextureRole::Data => [unorm(v[0]), unorm(v[1]), unorm(v[2]), unorm(v[3])],
            TextureRole::Normal => {
                let n = glam::Vec3::new(v[0], v[1], v[2]).try_normalize().unwrap_or(glam::Vec3::Z);
                let snorm = |x: f32| ((x * 0.5 + 0.5).clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
                [snorm(n.x), snorm(n.y), snorm(n.z), unorm(v[3])]
            }
        }
    };
    let mut level =
        Level { width: t.width, height: t.height, texels: t.rgba.chunks_exact(4).map(decode).collect() };
    for _ in 1..levels {
        let (w, h) = ((level.width / 2).max(1), (level.height / 2).max(1));
        let src = &level;
        let texels: Vec<[f32; 4]> = (0..h)
            .into_par_iter()
            .flat_map_iter(|y| {
                (0..w).map(move |x| {
                    let xs = [(2 * x).min(src.width - 1), (2 * x + 1).min(src.width - 1)];
                    let ys = [(2 * y).min(src.height - 1), (2 * y + 1).min(src.height - 1)];
                    let mut sum = [0.0f32; 4];
                    for yy in ys {
                        for xx in xs {
                            let p = src.texels[(yy * src.width + xx) as usize];
                            for c in 0..4 {
                                sum[c] += p[c];
                            }
                        }
                    }
                    sum.map(|s| s * 0.25)
                })
            })
            .collect();
        out.extend(texels.iter().flat_map(|&v| encode(v)));
        level = Level { width: w, height: h, texels };
    }
    out
}

/// Bumped when what the texture stage writes changes. 2: version-2 sections (pixel-format
/// header), block compression.
pub const TEXTURE_ALGORITHM: &str = "textures-2";

/// What each texture becomes under `ctx`'s settings.
pub fn choices(ctx: &super::BakeContext) -> Vec<Choice> {
    ctx.scene
        .textures
        .iter()
        .enumerate()
        .map(|(i, t)| choose(t, Usage::of(&ctx.materials, i as u32), ctx.settings.texture_format))
        .collect()
}

/// The texture stage: every texture's mip chain in its chosen format, in parallel (textures, and
/// rows of blocks within a level, which are independent, so the bytes do not depend on the
/// thread count).
pub fn stage(ctx: &super::BakeContext) -> super::Sections {
    let choices = choices(ctx);
    let stored: Vec<Vec<u8>> = ctx
        .scene
        .textures
        .par_iter()
        .zip(&choices)
        .map(|(t, c)| encode_texture(c.format, c.swizzle, &bc::encode(t, c, mip_chain(t))))
        .collect();
    let mut out = super::Sections::default();
    for (i, bytes) in stored.into_iter().enumerate() {
        out.push(kiln_format::sections::TEXTURE, i as u32, bytes);
    }
    out
}

/// The report's line for every texture: format, bytes and the error of mip 0 against the RGBA8
/// texels, decoded from the sections `sections` (baked or from the cache) with an independent
/// decoder. A texture over the bound is named in a warning on standard error.
pub fn reports(ctx: &super::BakeContext, sections: &super::Sections) -> Vec<TextureReport> {
    let choices = choices(ctx);
    let found: Vec<(usize, &super::BakedSection)> = sections
        .list
        .iter()
        .filter(|s| s.kind == kiln_format::sections::TEXTURE)
        .map(|s| (s.index as usize, s))
        .collect();
    let reports: Vec<TextureReport> = found
        .par_iter()
        .filter_map(|&(i, s)| {
            let t = ctx.scene.textures.get(i)?;
            let levels = kiln_format::scene::mip_levels(t.width, t.height);
            let data =
                kiln_format::sections::decode_texture(2, &s.bytes, t.width, t.height, levels, false).ok()?;
            let choice = &choices[i];
            let decoded = bc::decode_level(data.format, data.levels, t.width, t.height);
            let (psnr_db, mean_flip) =
                if data.format == PixelFormat::Rgba8 { (None, 0.0) } else { bc::error(t, choice, &decoded) };
            let within_bound = psnr_db.is_none_or(|p| p >= PSNR_BOUND_DB) && mean_flip <= FLIP_BOUND;
            Some(TextureReport {
                index: i as u32,
                name: t.name.clone(),
                width: t.width,
                height: t.height,
                format: data.format.name(),
                why: choice.why,
                bytes: s.bytes.len() as u64,
                rgba8_bytes: kiln_format::scene::mip_chain_bytes(t.width, t.height, levels).unwrap_or(0),
                psnr_db,
                mean_flip,
                within_bound,
            })
        })
        .collect();
    for r in reports.iter().filter(|r| !r.within_bound) {
        eprintln!(
            "warning: texture {} '{}' as {}: PSNR {:.1} dB, mean FLIP {:.4} (bound: {PSNR_BOUND_DB} dB, FLIP \
             {FLIP_BOUND}); --texture-format rgba8 keeps textures exact",
            r.index,
            r.name,
            r.format,
            r.psnr_db.unwrap_or(f64::INFINITY),
            r.mean_flip
        );
    }
    reports
}
