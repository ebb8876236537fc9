//! Block-compressed textures of a real scene: PICA PICA compiled with `--texture-format bc`,
//! every level of every texture decoded with `texture2ddecoder` (a decoder independent of both
//! the encoder, `intel_tex_2`, and the compiler's report decoder, `bcdec_rs`), swizzled as the
//! section header says, against the same scene compiled with `rgba8`; mip 0 also against the
//! source PNG read with `image`.

use kiln_compiler::settings::{Settings, TextureFormat};
use kiln_format::sections::{PixelFormat, Swizzle};
use kiln_format::{Checksums, KilnFile, SceneView};

/// The compile report's bound (`PSNR_BOUND_DB`): the test holds the encoder to it.
const PSNR_BOUND_DB: f64 = 35.0;
/// The report's FLIP bound.
const FLIP_BOUND: f64 = 0.05;

fn compile(format: TextureFormat) -> Option<Vec<u8>> {
    let gltf =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes/pica_pica/scene.gltf");
    if !gltf.is_file() {
        eprintln!("skipping: {} is not here", gltf.display());
        return None;
    }
    let scene = kiln_compiler::import::import(&gltf).unwrap();
    let settings = Settings { shaft_variants: Some(0), texture_format: format, ..Default::default() };
    Some(kiln_compiler::pipeline::compile_to_bytes(scene, settings, "pica").unwrap())
}

/// RGBA8 of a stored level, decoded block by block with texture2ddecoder (BGRA words).
fn decode(format: PixelFormat, bytes: &[u8], w: usize, h: usize) -> Vec<[u8; 4]> {
    let (bw, bh) = (w.div_ceil(4), h.div_ceil(4));
    let bb = format.block_bytes() as usize;
    assert_eq!(bytes.len(), bw * bh * bb, "level of {w}x{h}");
    let mut out = vec![[0u8; 4]; w * h];
    for by in 0..bh {
        for bx in 0..bw {
            let block = &bytes[(by * bw + bx) * bb..][..bb];
            let mut px = [0u32; 16];
            match format {
                PixelFormat::Bc7 => texture2ddecoder::decode_bc7_block(block, &mut px),
                PixelFormat::Bc5 => texture2ddecoder::decode_bc5_block(block, &mut px),
                PixelFormat::Bc4 => texture2ddecoder::decode_bc4_block(block, &mut px),
                PixelFormat::Rgba8 => unreachable!(),
            }
            for (i, p) in px.iter().enumerate() {
                let (x, y) = (bx * 4 + i % 4, by * 4 + i / 4);
                if x < w && y < h {
                    let [b, g, r, a] = p.to_le_bytes();
                    out[y * w + x] = match format {
                        PixelFormat::Bc7 => [r, g, b, a],
                        PixelFormat::Bc5 => [r, g, 0, 255],
                        _ => [r, 0, 0, 255],
                    };
                }
            }
        }
    }
    out
}

/// PSNR (dB) over `channels` of `a` against `b`; infinite when equal.
fn psnr(a: &[[u8; 4]], b: &[[u8; 4]], channels: &[usize]) -> f64 {
    let mut sq = 0f64;
    for (p, q) in a.iter().zip(b) {
        for &c in channels {
            let d = p[c] as f64 - q[c] as f64;
            sq += d * d;
        }
    }
    let mse = sq / (a.len() * channels.len()) as f64;
    if mse == 0.0 { f64::INFINITY } else { 10.0 * (255.0 * 255.0 / mse).log10() }
}

#[test]
fn pica_pica_bc_textures_stay_within_the_stated_error_bound_at_every_level() {
    let (Some(bc), Some(rgba8)) = (compile(TextureFormat::Bc), compile(TextureFormat::Rgba8)) else {
        return;
    };
    let (fb, fr) = (
        KilnFile::from_bytes(&bc, Checksums::Eager).unwrap(),
        KilnFile::from_bytes(&rgba8, Checksums::Eager).unwrap(),
    );
    let (vb, vr) = (SceneView::new(&fb).unwrap(), SceneView::new(&fr).unwrap());
    assert_eq!(vb.manifest.textures.len(), 6);
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes/pica_pica");
    let (mut bc_bytes, mut rgba8_bytes) = (0usize, 0usize);
    for (i, info) in vb.manifest.textures.iter().enumerate() {
        let (tb, tr) = (vb.texture(i).unwrap(), vr.texture(i).unwrap());
        assert_eq!(tr.format, PixelFormat::Rgba8);
        assert!(tb.format.is_block_compressed(), "{}: {:?}", info.name, tb.format);
        bc_bytes += tb.levels.len();
        rgba8_bytes += tr.levels.len();
        // The sampled channels that come from stored ones are what the shaders read.
        let used: Vec<usize> = (0..4).filter(|&k| (tb.swizzle[k] as u8) < 4).collect();
        let sampled = |p: [u8; 4]| {
            tb.swizzle.map(|s| match s {
                Swizzle::Zero => 0,
                Swizzle::One => 255,
                c => p[c as usize],
            })
        };
        let (lb, lr) = (
            tb.level_slices(info.width, info.height, info.mip_levels),
            tr.level_slices(info.width, info.height, info.mip_levels),
        );
        for l in 0..info.mip_levels as usize {
            let (w, h) = ((info.width >> l).max(1) as usize, (info.height >> l).max(1) as usize);
            let got: Vec<[u8; 4]> = decode(tb.format, lb[l], w, h).into_iter().map(sampled).collect();
            let want: Vec<[u8; 4]> = lr[l].chunks_exact(4).map(|p| [p[0], p[1], p[2], p[3]]).collect();
            let p = psnr(&got, &want, &used);
            if l == 0 {
                eprintln!("{} {}x{} {:?}: mip 0 PSNR {p:.2} dB", info.name, w, h, tb.format);
            }
            assert!(p >= PSNR_BOUND_DB, "{} level {l} ({w}x{h}): PSNR {p:.2} dB", info.name);
        }
        // Mip 0 against the source image itself, read here with `image`.
        let src = image::open(dir.join(&info.name)).unwrap().into_rgba8();
        let (w, h) = (info.width as usize, info.height as usize);
        assert_eq!(src.dimensions(), (info.width, info.height));
        let got: Vec<[u8; 4]> = decode(tb.format, lb[0], w, h).into_iter().map(sampled).collect();
        let want: Vec<[u8; 4]> = src.pixels().map(|p| p.0).collect();
        // Colour as seen (sRGB decoded, premultiplied by alpha), data as the values.
        let srgb = info.color_space == kiln_format::manifest::ColorSpace::Srgb;
        let lin = |c: u8| {
            let c = c as f32 / 255.0;
            if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
        };
        let image_of = |px: &[[u8; 4]]| -> Vec<f32> {
            px.iter()
                .flat_map(|p| {
                    if srgb {
                        let a = p[3] as f32 / 255.0;
                        [lin(p[0]) * a, lin(p[1]) * a, lin(p[2]) * a]
                    } else {
                        [p[0] as f32 / 255.0, p[1] as f32 / 255.0, p[2] as f32 / 255.0]
                    }
                })
                .collect()
        };
        let masked = |px: &[[u8; 4]]| -> Vec<[u8; 4]> {
            px.iter()
                .map(|p| [0, 1, 2, 3].map(|k| if used.contains(&k) { p[k] } else { sampled([0; 4])[k] }))
                .collect()
        };
        let (a, b) = (image_of(&masked(&want)), image_of(&masked(&got)));
        let flip = kiln_metrics::ldr_flip(
            kiln_metrics::RgbImage { width: info.width, height: info.height, pixels: &a },
            kiln_metrics::RgbImage { width: info.width, height: info.height, pixels: &b },
        )
        .unwrap();
        let p0 = psnr(&got, &want, &used);
        eprintln!("{}: against the PNG, PSNR {p0:.2} dB, mean FLIP {flip:.4}", info.name);
        assert!(p0 >= PSNR_BOUND_DB && flip <= FLIP_BOUND, "{}: PSNR {p0:.2} dB, FLIP {flip:.4}", info.name);
    }
    eprintln!("textures: {bc_bytes} bytes as BC, {rgba8_bytes} as RGBA8");
    // A quarter of RGBA8 (BC7 and BC5 are a quarter of it but for the levels under 4x4, padded to
    // a whole block).
    assert!(bc_bytes as f64 <= 0.2501 * rgba8_bytes as f64, "{bc_bytes} vs {rgba8_bytes}");
}
