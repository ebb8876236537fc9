//! The `environment` stage: from the scene's [`EnvironmentImage`], the radiance map at the
//! budgeted width (`--environment-res`), its GGX-prefiltered levels for the split-sum specular,
//! its irradiance as nine spherical harmonics and the alias table that draws directions in
//! proportion to its light (FORMAT.md, "Environment"; `kiln_format::environment`).
//!
//! - Resampling averages the source over each target texel's rectangle in (u, v), fractional
//!   overlaps included, after the rotation about +y; a map is never enlarged.
//! - Prefiltered level i (of [`LEVELS`], level 0 [`FILTERED_WIDTH`] wide at most, each next half
//!   as wide) holds, in direction n, ∫ L(l) D(h) (n·l)⁺ dl / ∫ D(h) (n·l)⁺ dl for GGX's D with
//!   α = (i / (LEVELS − 1))² and h the half vector of n and l (the split sum's assumption n = v).
//!   Narrow lobes (α below 0.15: roughness 0.2) are estimated with [`FILTER_SAMPLES`] GGX samples
//!   of a fixed Hammersley set, each read from the radiance map's box-filtered pyramid at the
//!   level its solid angle covers (Křivánek and Colbert's filtered importance sampling, as
//!   Karis's split sum does); wide ones are summed over every texel of the pyramid level at most
//!   four times as wide as the output (its mip blur would bias the sampled estimate by several
//!   per cent). Level 0 is the map averaged down to its width.
//! - The harmonics project the map (each texel weighted by its solid angle) and convolve with the
//!   clamped cosine (Ramamoorthi and Hanrahan: bands scaled by 1, 2/3, 1/4 after dividing by π).
//! - The table's cells ([`TABLE_WIDTH`] wide at most) are drawn in proportion to their mean
//!   luminance times their solid angle; a drawn direction is uniform in (u, v) within the cell.
//!
//! Every sum runs in a fixed order per texel (rows in parallel), so the bytes do not depend on
//! the thread count.

use glam::Vec3;
use kiln_format::environment::{
    Environment, EnvironmentCell, EnvironmentHeader, alias_table, direction_to_uv, sh_basis,
    texel_solid_angle, uv_to_direction,
};
use kiln_format::probes::{decode_rgb9e5, encode_rgb9e5};
use kiln_format::sections::{ENVIRONMENT_FILTERED, ENVIRONMENT_HEADER, ENVIRONMENT_MAP, ENVIRONMENT_TABLE};
use rayon::prelude::*;

use super::{BakeContext, Sections};
use crate::ir::EnvironmentImage;

/// Prefiltered levels: roughness 0, 0.2, …, 1.
pub const LEVELS: u32 = 6;
/// Width of prefiltered level 0, at most.
pub const FILTERED_WIDTH: u32 = 256;
/// Width of the sampling table, at most.
pub const TABLE_WIDTH: u32 = 512;
/// GGX samples per prefiltered texel of the narrow lobes (each read from the pyramid level its
/// solid angle covers: few samples suffice; the brute-force levels use none).
pub const FILTER_SAMPLES: u32 = 256;

/// What the stage bakes, kept for the stages that light with it (the probes).
#[derive(Debug, Clone)]
pub struct BakedEnvironment {
    /// The header.
    pub header: EnvironmentHeader,
    /// The radiance map, `E5B9G9R9`.
    pub map: Vec<u32>,
    /// The prefiltered levels, `E5B9G9R9`.
    pub filtered: Vec<u32>,
    /// The sampling table.
    pub table: Vec<EnvironmentCell>,
    /// Mean radiance over the sphere of the baked map (solid-angle weighted).
    pub mean: [f32; 3],
}

impl BakedEnvironment {
    /// The baked sections as a reader sees them (radiance, density, sampling).
    pub fn view(&self) -> Environment<'_> {
        Environment { header: self.header, map: &self.map, filtered: &self.filtered, table: &self.table }
    }
}

/// A linear RGB image in f32, rows of `width`.
#[derive(Debug, Clone)]
struct Image {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
}

impl Image {
    fn at(&self, x: i64, y: i64) -> Vec3 {
        let x = x.rem_euclid(self.width as i64) as u32;
        let y = y.clamp(0, self.height as i64 - 1) as u32;
        self.pixels[(y * self.width + x) as usize]
    }

    /// Bilinear at (u, v), wrapping in u and clamping in v.
    fn bilinear(&self, u: f32, v: f32) -> Vec3 {
        let (x, y) = (u * self.width as f32 - 0.5, v * self.height as f32 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.at(x0, y0).lerp(self.at(x0 + 1, y0), fx);
        let bottom = self.at(x0, y0 + 1).lerp(self.at(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }

    /// Half the width and height, each texel the mean of four.
    fn halve(&self) -> Image {
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let pixels = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i64 * 2, (i / w) as i64 * 2);
                (self.at(x, y) + self.at(x + 1, y) + self.at(x, y + 1) + self.at(x + 1, y + 1)) * 0.25
            })
            .collect();
        Image { width: w, height: h, pixels }
    }
}

/// Source texels overlapping [a, b) (in source texel units) with their overlap lengths; indices
/// wrap modulo `n` when `wrap`, else clamp to the image.
fn coverage(a: f64, b: f64, n: u32, wrap: bool) -> Vec<(u32, f64)> {
    let mut out = Vec::new();
    let mut j = a.floor();
    while j < b {
        let w = (j + 1.0).min(b) - j.max(a);
        if w > 0.0 {
            let i = if wrap { (j as i64).rem_euclid(n as i64) } else { (j as i64).clamp(0, n as i64 - 1) };
            out.push((i as u32, w));
        }
        j += 1.0;
    }
    out
}

/// `src` averaged over each texel of a `width` × `width / 2` map, turned by `rotation_degrees`
/// about +y by the right-hand rule (counter-clockwise seen from above: +90° takes what lay along
/// −z to −x; the target direction at u sees the source at u + rotation / 360).
fn resample(src: &Image, width: u32, rotation_degrees: f32) -> Image {
    if width == src.width && rotation_degrees.rem_euclid(360.0) == 0.0 {
        return src.clone();
    }
    let height = width / 2;
    let shift = (-rotation_degrees as f64 / 360.0).rem_euclid(1.0);
    let cols: Vec<Vec<(u32, f64)>> = (0..width)
        .map(|x| {
            let (u0, u1) = (x as f64 / width as f64 - shift, (x + 1) as f64 / width as f64 - shift);
            coverage(u0 * src.width as f64, u1 * src.width as f64, src.width, true)
        })
        .collect();
    let pixels = (0..height)
        .into_par_iter()
        .flat_map_iter(|y| {
            let rows = coverage(
                y as f64 / height as f64 * src.height as f64,
                (y + 1) as f64 / height as f64 * src.height as f64,
                src.height,
                false,
            );
            let cols = &cols;
            (0..width).map(move |x| {
                let (mut sum, mut total) = ([0f64; 3], 0f64);
                for &(r, wr) in &rows {
                    for &(c, wc) in &cols[x as usize] {
                        let p = src.pixels[(r * src.width + c) as usize];
                        let w = wr * wc;
                        for k in 0..3 {
                            sum[k] += w * p[k] as f64;
                        }
                        total += w;
                    }
                }
                Vec3::from(sum.map(|s| (s / total) as f32))
            })
        })
        .collect();
    Image { width, height, pixels }
}

/// Van der Corput's radical inverse of `i` in base 2.
fn radical_inverse(i: u32) -> f32 {
    (i.reverse_bits() as f64 / 4_294_967_296.0) as f32
}

/// One prefiltered texel: direction `n`, GGX α, the pyramid of the radiance map (level 0 first).
fn prefilter(n: Vec3, alpha: f32, pyramid: &[Image]) -> Vec3 {
    // An orthonormal basis around n (Duff et al. 2017).
    let (t, b) = n.any_orthonormal_pair();
    let a2 = alpha * alpha;
    let base = &pyramid[0];
    let texel = (std::f32::consts::TAU / base.width as f32) * (std::f32::consts::PI / base.height as f32);
    let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
    for i in 0..FILTER_SAMPLES {
        let (xi1, xi2) = ((i as f32 + 0.5) / FILTER_SAMPLES as f32, radical_inverse(i));
        let cos_h = ((1.0 - xi1) / (1.0 + (a2 - 1.0) * xi1)).max(0.0).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * xi2;
        let h = t * (sin_h * phi.cos()) + b * (sin_h * phi.sin()) + n * cos_h;
        let l = (2.0 * n.dot(h) * h - n).normalize();
        let nl = n.dot(l);
        if nl <= 0.0 {
            continue;
        }
        // Density of l: D(h) cos_h / (4 v·h) with v = n, i.e. D(h) / 4.
        let d = a2 / (std::f32::consts::PI * ((a2 - 1.0) * cos_h * cos_h + 1.0).powi(2));
        let solid = 1.0 / (FILTER_SAMPLES as f32 * d * 0.25);
        let sin_l = (1.0 - l.y * l.y).max(1e-4).sqrt();
        let lod = (0.5 * (solid / (texel * sin_l)).log2() + 1.0).clamp(0.0, (pyramid.len() - 1) as f32);
        let [u, v] = direction_to_uv(l);
        let (l0, f) = (lod.floor() as usize, lod.fract());
        let mut c = pyramid[l0].bilinear(u, v);
        if f > 0.0 && l0 + 1 < pyramid.len() {
            c = c.lerp(pyramid[l0 + 1].bilinear(u, v), f);
        }
        sum += c * nl;
        weight += nl;
    }
    if weight > 0.0 { sum / weight } else { Vec3::ZERO }
}

/// One prefiltered texel by brute force: the lobe integral summed over every texel of `src` (a
/// pyramid level whose texels are small against the lobe), each texel's direction at its centre
/// and its exact solid angle. Used where the lobe is wide (few output texels, a coarse source),
/// where filtered importance sampling's mip blur would bias it.
fn convolve(n: Vec3, alpha: f32, src: &Image, dirs: &[(Vec3, f32)]) -> Vec3 {
    let a2 = alpha * alpha;
    let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
    for (&(l, dw), &c) in dirs.iter().zip(&src.pixels) {
        let nl = n.dot(l);
        if nl <= 0.0 {
            continue;
        }
        let h = n + l;
        let nh2 = n.dot(h).powi(2) / h.length_squared();
        let d = a2 / ((a2 - 1.0) * nh2 + 1.0).powi(2);
        let w = d * nl * dw;
        sum += c * w;
        weight += w;
    }
    if weight > 0.0 { sum / weight } else { Vec3::ZERO }
}

/// The centre direction and solid angle of every texel of a `width` × `height` map.
fn texel_directions(width: u32, height: u32) -> Vec<(Vec3, f32)> {
    (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let d = uv_to_direction((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32);
            (d, texel_solid_angle(y, width, height) as f32)
        })
        .collect()
}

/// Levels whose GGX α is at least this are convolved by brute force (roughness 0.4 and up).
const CONVOLVE_ALPHA: f32 = 0.15;

/// Bakes `env` with a radiance map at most `max_width` wide.
pub fn bake(env: &EnvironmentImage, max_width: u32) -> BakedEnvironment {
    let src = Image {
        width: env.width,
        height: env.height,
        pixels: env.pixels.iter().map(|&p| Vec3::from(p)).collect(),
    };
    let width = (max_width.min(env.width) & !1).max(2);
    let map = resample(&src, width, env.rotation_degrees);
    let map_texels: Vec<u32> = map.pixels.par_iter().map(|p| encode_rgb9e5(p.to_array())).collect();
    // The mean of the stored texels: rows summed in parallel, then in order.
    let rows: Vec<([f64; 3], f64)> = map_texels
        .par_chunks(width as usize)
        .enumerate()
        .map(|(y, row)| {
            let dw = texel_solid_angle(y as u32, width, width / 2);
            let mut sum = [0f64; 3];
            for &t in row {
                for (s, c) in sum.iter_mut().zip(decode_rgb9e5(t)) {
                    *s += c as f64 * dw;
                }
            }
            (sum, dw * row.len() as f64)
        })
        .collect();
    let (mut sum, mut total) = ([0f64; 3], 0f64);
    for (s, w) in rows {
        for c in 0..3 {
            sum[c] += s[c];
        }
        total += w;
    }
    let mean = sum.map(|s| (s / total) as f32);
    // The pyramid the prefilter reads, from the map itself.
    let mut pyramid = vec![map.clone()];
    while let Some(next) = pyramid.last().filter(|l| l.width > 8).map(Image::halve) {
        pyramid.push(next);
    }
    let fw = FILTERED_WIDTH.min(width);
    let (tw, th) = (TABLE_WIDTH.min(width), TABLE_WIDTH.min(width) / 2);
    let mut header = EnvironmentHeader {
        map: [width, width / 2, 0, 0],
        filtered: [fw, fw / 2, LEVELS, width * (width / 2)],
        table: [tw, th, 0, 0],
        sh: [[0.0; 4]; 9],
    };
    let level0 = resample(&map, fw, 0.0);
    let mut filtered: Vec<u32> = level0.pixels.iter().map(|p| encode_rgb9e5(p.to_array())).collect();
    for i in 1..LEVELS {
        let [w, h] = header.filtered_extent(i);
        let roughness = i as f32 / (LEVELS - 1) as f32;
        let alpha = roughness * roughness;
        // The brute-force source: the pyramid's level at most four times the output's width.
        let src = pyramid.iter().find(|l| l.width <= 4 * w).unwrap_or(&pyramid[pyramid.len() - 1]);
        let dirs = if alpha >= CONVOLVE_ALPHA { texel_directions(src.width, src.height) } else { Vec::new() };
        let level: Vec<u32> = (0..h)
            .into_par_iter()
            .flat_map_iter(|y| {
                let (pyramid, dirs) = (&pyramid, &dirs);
                (0..w).map(move |x| {
                    let n = uv_to_direction((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                    let c = if dirs.is_empty() {
                        prefilter(n, alpha, pyramid)
                    } else {
                        convolve(n, alpha, src, dirs)
                    };
                    encode_rgb9e5(c.to_array())
                })
            })
            .collect();
        filtered.extend(level);
    }
    // Irradiance harmonics from prefiltered level 0's texels (plenty for band 2), each texel
    // split into 4 x 4 parts of their own direction and exact solid angle: the integral of the
    // piecewise-constant map, not a midpoint rule over its texels.
    const SPLIT: u32 = 4;
    let (sw, shh) = (level0.width * SPLIT, level0.height * SPLIT);
    let rows: Vec<[[f64; 3]; 9]> = (0..shh)
        .into_par_iter()
        .map(|y| {
            let dw = texel_solid_angle(y, sw, shh);
            let mut row = [[0f64; 3]; 9];
            for x in 0..sw {
                let d = uv_to_direction((x as f32 + 0.5) / sw as f32, (y as f32 + 0.5) / shh as f32);
                let l = level0.pixels[((y / SPLIT) * level0.width + x / SPLIT) as usize];
                for (k, b) in sh_basis(d).iter().enumerate() {
                    for c in 0..3 {
                        row[k][c] += l[c] as f64 * *b as f64 * dw;
                    }
                }
            }
            row
        })
        .collect();
    let mut sh = [[0f64; 3]; 9];
    for row in &rows {
        for k in 0..9 {
            for c in 0..3 {
                sh[k][c] += row[k][c];
            }
        }
    }
    let band = [1.0, 2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0, 0.25, 0.25, 0.25, 0.25, 0.25];
    header.sh = std::array::from_fn(|k| {
        let c = sh[k].map(|v| (v * band[k]) as f32);
        [c[0], c[1], c[2], 0.0]
    });
    // The sampling table.
    let cells = resample(&map, tw, 0.0);
    let weights: Vec<f64> = (0..tw * th)
        .map(|i| {
            let p = cells.pixels[i as usize].to_array();
            kiln_format::gpu::luminance(p) as f64 * texel_solid_angle(i / tw, tw, th)
        })
        .collect();
    let total: f64 = weights.iter().sum();
    let scale = (tw * th) as f64 / (2.0 * std::f64::consts::PI * std::f64::consts::PI);
    let density: Vec<f32> =
        weights.iter().map(|w| if total > 0.0 { (w / total * scale) as f32 } else { 0.0 }).collect();
    let table = alias_table(&weights)
        .into_iter()
        .enumerate()
        .map(|(i, (keep, alias))| EnvironmentCell {
            keep: keep.clamp(0.0, 1.0),
            alias,
            density: density[i],
            alias_density: density[alias as usize],
        })
        .collect();
    BakedEnvironment { header, map: map_texels, filtered, table, mean }
}

/// The stage: the sections of the context's baked environment (none without an environment).
pub fn stage(ctx: &BakeContext) -> Sections {
    let mut out = Sections::default();
    let Some(env) = ctx.environment() else { return out };
    out.push(ENVIRONMENT_HEADER, 0, bytemuck::bytes_of(&env.header).to_vec());
    out.push(ENVIRONMENT_MAP, 0, bytemuck::cast_slice(&env.map).to_vec());
    out.push(ENVIRONMENT_FILTERED, 0, bytemuck::cast_slice(&env.filtered).to_vec());
    out.push(ENVIRONMENT_TABLE, 0, bytemuck::cast_slice(&env.table).to_vec());
    out
}
