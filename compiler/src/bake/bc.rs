//! Block compression of textures: which format each texture becomes (from the material slots
//! that read it), encoding through Intel's ISPC texture compressor (`intel_tex_2`), and the error
//! of mip 0 against the RGBA8 texels, measured through an independent decoder (`bcdec_rs`).

use intel_tex_2::{RSurface, RgSurface, RgbaSurface, bc4, bc5, bc7};
use kiln_format::sections::{GpuMaterial, NO_TEXTURE, PixelFormat, Swizzle};
use rayon::prelude::*;
use serde::Serialize;

use crate::ir::{Texture, TextureRole};
use crate::settings::TextureFormat;

/// Which material slots read a texture.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Usage {
    /// Base colour or emissive (sRGB colour).
    pub color: bool,
    /// Metallic-roughness (G roughness, B metalness).
    pub metallic_roughness: bool,
    /// Tangent-space normal map.
    pub normal: bool,
    /// Occlusion (R).
    pub occlusion: bool,
    /// Clear coat strength (R).
    pub clearcoat: bool,
    /// Clear coat roughness (G).
    pub clearcoat_roughness: bool,
    /// Transmission (R).
    pub transmission: bool,
}

impl Usage {
    /// The slots of texture `i` in `materials`.
    pub fn of(materials: &[GpuMaterial], i: u32) -> Usage {
        let mut u = Usage::default();
        for m in materials {
            u.color |= m.base_color_texture == i || m.emissive_texture == i;
            u.metallic_roughness |= m.metallic_roughness_texture == i;
            u.normal |= m.normal_texture == i;
            u.occlusion |= m.occlusion_texture == i;
            u.clearcoat |= m.clearcoat_texture == i;
            u.clearcoat_roughness |= m.clearcoat_roughness_texture == i;
            u.transmission |= m.transmission_texture == i;
        }
        debug_assert!(i != NO_TEXTURE);
        u
    }

    /// As bytes, for the stage key.
    pub fn bits(self) -> u8 {
        self.color as u8
            | (self.metallic_roughness as u8) << 1
            | (self.normal as u8) << 2
            | (self.occlusion as u8) << 3
            | (self.clearcoat as u8) << 4
            | (self.clearcoat_roughness as u8) << 5
            | (self.transmission as u8) << 6
    }
}

/// What a texture becomes: its pixel format, the swizzle that gives the shaders the channels
/// where they read them, and which source channels (RGBA8 indices) are encoded, in stored order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Choice {
    /// Stored format.
    pub format: PixelFormat,
    /// What sampled R, G, B, A return.
    pub swizzle: [Swizzle; 4],
    /// Source channel of each stored channel.
    pub channels: Vec<usize>,
    /// Why, for `kiln plan` and the report.
    pub why: &'static str,
}

/// The format of a texture of `role` read by the slots in `usage`. One image used in two roles
/// is two textures (the importer keys textures by image and role), so only a data texture can be
/// read by two slots (an occlusion-roughness-metallic image): it keeps all three channels.
pub fn choose(t: &Texture, usage: Usage, setting: TextureFormat) -> Choice {
    let rgba8 = |why| Choice {
        format: PixelFormat::Rgba8,
        swizzle: Swizzle::IDENTITY,
        channels: vec![0, 1, 2, 3],
        why,
    };
    if setting == TextureFormat::Rgba8 {
        return rgba8("--texture-format rgba8");
    }
    use Swizzle::{G, One, R, Zero};
    match t.role {
        TextureRole::Color => Choice {
            format: PixelFormat::Bc7,
            swizzle: Swizzle::IDENTITY,
            channels: vec![0, 1, 2, 3],
            why: "colour: BC7 sRGB with alpha",
        },
        // x, y; the shaders reconstruct z = sqrt(1 - x² - y²) for every normal map.
        TextureRole::Normal => Choice {
            format: PixelFormat::Bc5,
            swizzle: [R, G, Zero, One],
            channels: vec![0, 1],
            why: "normal map: BC5 of x, y (z reconstructed)",
        },
        // The stored channels are those some slot reads: R (occlusion, clear coat, transmission),
        // G (roughness, clear coat roughness), B (metalness).
        TextureRole::Data => {
            let coat = usage.clearcoat || usage.clearcoat_roughness || usage.transmission;
            let red = usage.occlusion || usage.clearcoat || usage.transmission;
            let green = usage.metallic_roughness || usage.clearcoat_roughness;
            let why = |plain, coated| if coat { coated } else { plain };
            match (red, green, usage.metallic_roughness) {
                (true, _, true) => Choice {
                    format: PixelFormat::Bc7,
                    swizzle: [R, G, Swizzle::B, One],
                    channels: vec![0, 1, 2],
                    why: why(
                        "occlusion + metallic-roughness: BC7 linear of R, G, B",
                        "clear coat or transmission with metallic-roughness: BC7 linear of R, G, B",
                    ),
                },
                (false, _, true) => Choice {
                    format: PixelFormat::Bc5,
                    swizzle: [Zero, R, G, One],
                    channels: vec![1, 2],
                    why: why(
                        "metallic-roughness: BC5 of G (roughness), B (metalness)",
                        "clear coat roughness with metallic-roughness: BC5 of G, B",
                    ),
                },
                (true, true, false) => Choice {
                    format: PixelFormat::Bc5,
                    swizzle: [R, G, Zero, One],
                    channels: vec![0, 1],
                    why: "clear coat (or transmission) and the coat's roughness: BC5 of R, G",
                },
                (true, false, false) => Choice {
                    format: PixelFormat::Bc4,
                    swizzle: [R, R, R, One],
                    channels: vec![0],
                    why: why("occlusion: BC4 of R", "clear coat or transmission: BC4 of R"),
                },
                (false, true, false) => Choice {
                    format: PixelFormat::Bc4,
                    swizzle: [Zero, R, Zero, One],
                    channels: vec![1],
                    why: "clear coat roughness: BC4 of G",
                },
                (false, false, false) => rgba8("read by no material slot: kept RGBA8"),
            }
        }
    }
}

/// The channels `channels` of a `width × height` RGBA8 level, padded to whole 4×4 blocks by
/// repeating the last column and row (what BC encoders expect; the padding is never sampled).
fn padded(rgba: &[u8], width: u32, height: u32, channels: &[usize]) -> (Vec<u8>, u32, u32) {
    let (pw, ph) = (width.div_ceil(4) * 4, height.div_ceil(4) * 4);
    let n = channels.len();
    let mut out = vec![0u8; pw as usize * ph as usize * n];
    for y in 0..ph {
        let sy = y.min(height - 1);
        for x in 0..pw {
            let sx = x.min(width - 1);
            let src = ((sy * width + sx) * 4) as usize;
            let dst = ((y * pw + x) as usize) * n;
            for (k, &c) in channels.iter().enumerate() {
                out[dst + k] = rgba[src + c];
            }
        }
    }
    (out, pw, ph)
}

/// Rows of blocks compressed per task: enough work per call to amortise it, small enough to
/// spread a 2048² level over the worker threads. Blocks are independent, so the output does not
/// depend on how the rows are split.
const BLOCK_ROWS_PER_TASK: u32 = 8;

/// Encodes one RGBA8 level of `width × height` as `choice` says.
fn encode_level(choice: &Choice, rgba: &[u8], width: u32, height: u32, alpha: bool) -> Vec<u8> {
    let (data, pw, ph) = padded(rgba, width, height, &choice.channels);
    let n = choice.channels.len() as u32;
    let block_rows = ph / 4;
    let row_bytes = (pw / 4 * choice.format.block_bytes()) as usize;
    let tasks: Vec<u32> = (0..block_rows.div_ceil(BLOCK_ROWS_PER_TASK)).collect();
    let settings = if alpha { bc7::alpha_basic_settings() } else { bc7::opaque_basic_settings() };
    let parts: Vec<Vec<u8>> = tasks
        .par_iter()
        .map(|&t| {
            let first = t * BLOCK_ROWS_PER_TASK;
            let rows = BLOCK_ROWS_PER_TASK.min(block_rows - first);
            let stride = pw * n;
            let bytes = &data[(first * 4 * stride) as usize..((first + rows) * 4 * stride) as usize];
            let (w, h) = (pw, rows * 4);
            match choice.format {
                PixelFormat::Bc7 => {
                    // BC7 needs RGBA input: data textures (three channels) get opaque alpha.
                    let rgba: Vec<u8> = if n == 4 {
                        bytes.to_vec()
                    } else {
                        bytes.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect()
                    };
                    bc7::compress_blocks(
                        &settings,
                        &RgbaSurface { data: &rgba, width: w, height: h, stride: w * 4 },
                    )
                }
                PixelFormat::Bc5 => {
                    bc5::compress_blocks(&RgSurface { data: bytes, width: w, height: h, stride: w * 2 })
                }
                PixelFormat::Bc4 => {
                    bc4::compress_blocks(&RSurface { data: bytes, width: w, height: h, stride: w })
                }
                PixelFormat::Rgba8 => unreachable!("RGBA8 levels are stored as they are"),
            }
        })
        .collect();
    let out: Vec<u8> = parts.concat();
    debug_assert_eq!(out.len(), row_bytes * block_rows as usize);
    out
}

/// The stored mip chain of `t` (RGBA8 chain `chain`, level 0 first) in `choice`'s format.
pub fn encode(t: &Texture, choice: &Choice, chain: Vec<u8>) -> Vec<u8> {
    if choice.format == PixelFormat::Rgba8 {
        return chain;
    }
    // Alpha settings spend bits on alpha only where the colour texture has some.
    let alpha = choice.channels.len() == 4 && t.rgba.chunks_exact(4).any(|p| p[3] != 255);
    let levels = kiln_format::scene::mip_levels(t.width, t.height);
    let mut out = Vec::new();
    let mut offset = 0usize;
    for l in 0..levels {
        let (w, h) = ((t.width >> l).max(1), (t.height >> l).max(1));
        let n = (w * h * 4) as usize;
        out.extend(encode_level(choice, &chain[offset..offset + n], w, h, alpha));
        offset += n;
    }
    out
}

/// Decodes one stored level to RGBA8 of its stored channels (`bcdec_rs`, independent of the
/// encoder): the format crate's, which the player's reference path tracer also uses.
pub use kiln_format::sections::decode_level;

/// A texture's line in the compile report.
#[derive(Debug, Clone, Serialize)]
pub struct TextureReport {
    /// Texture number.
    pub index: u32,
    /// Image name.
    pub name: String,
    /// Mip 0 size.
    pub width: u32,
    /// Mip 0 size.
    pub height: u32,
    /// Stored format.
    pub format: &'static str,
    /// Why that format.
    pub why: &'static str,
    /// Bytes of the section.
    pub bytes: u64,
    /// Bytes the RGBA8 mip chain takes.
    pub rgba8_bytes: u64,
    /// PSNR (dB) of mip 0 over the stored channels against the RGBA8 texels; `None` when exact.
    pub psnr_db: Option<f64>,
    /// Mean LDR-FLIP of mip 0 against the RGBA8 texels (colour premultiplied by alpha, data as
    /// linear values); 0 when exact.
    pub mean_flip: f64,
    /// Whether the error is within [`PSNR_BOUND_DB`] and [`FLIP_BOUND`].
    pub within_bound: bool,
}

/// The smallest PSNR (dB) of a block-compressed mip 0 that passes without a warning. Measured on
/// the shared scenes' textures (docs/testing.md): pica_pica's are 41 to 60 dB.
pub const PSNR_BOUND_DB: f64 = 35.0;
/// The largest mean LDR-FLIP of a block-compressed mip 0 that passes without a warning.
pub const FLIP_BOUND: f64 = 0.05;

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// PSNR (dB) and mean LDR-FLIP of `decoded` mip 0 (stored channels, [`decode_level`]) against
/// the source RGBA8 texels of `t`, over the channels `choice` stores.
pub fn error(t: &Texture, choice: &Choice, decoded: &[u8]) -> (Option<f64>, f64) {
    let n = choice.channels.len();
    let mut sq = 0f64;
    for (src, dec) in t.rgba.chunks_exact(4).zip(decoded.chunks_exact(4)) {
        for (k, &c) in choice.channels.iter().enumerate() {
            let d = src[c] as f64 - dec[k] as f64;
            sq += d * d;
        }
    }
    let mse = sq / (t.rgba.len() / 4 * n) as f64;
    let psnr = (mse > 0.0).then(|| 10.0 * (255.0f64 * 255.0 / mse).log10());
    // FLIP images: colour as seen (linear, premultiplied by alpha); data as linear values, two
    // channels in R, G and one channel grey.
    let image = |px: &mut dyn Iterator<Item = [u8; 4]>| -> Vec<f32> {
        px.flat_map(|p| match (t.role, n) {
            (TextureRole::Color, _) => {
                let a = p[3] as f32 / 255.0;
                [srgb_to_linear(p[0]) * a, srgb_to_linear(p[1]) * a, srgb_to_linear(p[2]) * a]
            }
            (_, 1) => [p[0] as f32 / 255.0; 3],
            (_, 2) => [p[0] as f32 / 255.0, p[1] as f32 / 255.0, 0.0],
            _ => [p[0] as f32 / 255.0, p[1] as f32 / 255.0, p[2] as f32 / 255.0],
        })
        .collect()
    };
    // FLIP keeps several float images of its input's size: over a large texture (an 8192² one
    // took 6 GiB and a minute) it is measured on a 4 x 4 grid of tiles spread over the image,
    // their means weighted by area, rather than on all of it.
    let tiles = flip_tiles(t.width, t.height);
    let mut weighted = 0.0;
    let mut area = 0.0;
    for (x0, y0, w, h) in tiles {
        let texels = |src| tile_texels(src, t.width, (x0, y0, w, h));
        let reference = image(&mut texels(&t.rgba).map(|s| {
            let mut p = [0u8; 4];
            for (k, &c) in choice.channels.iter().enumerate() {
                p[k] = s[c];
            }
            if n < 4 {
                p[3] = 255;
            }
            p
        }));
        let test = image(&mut texels(decoded).map(|d| [d[0], d[1], d[2], if n < 4 { 255 } else { d[3] }]));
        let flip = kiln_metrics::ldr_flip(
            kiln_metrics::RgbImage { width: w, height: h, pixels: &reference },
            kiln_metrics::RgbImage { width: w, height: h, pixels: &test },
        )
        .unwrap_or(f64::NAN);
        weighted += flip * (w * h) as f64;
        area += (w * h) as f64;
    }
    (psnr, weighted / area)
}

/// The RGBA8 texels of `tile` (x, y, width, height) of an image `width` wide, rows in order.
fn tile_texels(
    src: &[u8],
    width: u32,
    (x0, y0, w, h): (u32, u32, u32, u32),
) -> impl Iterator<Item = [u8; 4]> + '_ {
    (y0..y0 + h)
        .flat_map(move |y| (x0..x0 + w).map(move |x| ((y * width + x) * 4) as usize))
        .map(move |i| [src[i], src[i + 1], src[i + 2], src[i + 3]])
}

/// Texels a texture's FLIP is measured over whole: 1024².
const FLIP_WHOLE_TEXELS: u32 = 1 << 20;

/// The regions `(x, y, width, height)` FLIP measures: the whole image up to
/// [`FLIP_WHOLE_TEXELS`], else 16 tiles of at most 256 × 256 centred in the cells of a 4 × 4 grid.
fn flip_tiles(width: u32, height: u32) -> Vec<(u32, u32, u32, u32)> {
    if width.saturating_mul(height) <= FLIP_WHOLE_TEXELS {
        return vec![(0, 0, width, height)];
    }
    let (w, h) = ((width / 4).clamp(1, 256), (height / 4).clamp(1, 256));
    let mut out = Vec::with_capacity(16);
    for j in 0..4 {
        for i in 0..4 {
            let cx = (2 * i + 1) * width / 8;
            let cy = (2 * j + 1) * height / 8;
            out.push((
                cx.saturating_sub(w / 2).min(width - w),
                cy.saturating_sub(h / 2).min(height - h),
                w,
                h,
            ));
        }
    }
    out
}
