//! Block-compressed textures on the GPU: a textured floor (base colour with alpha, a
//! metallic-roughness map and a normal map, sizes that are not multiples of the 4×4 block)
//! compiled with `--texture-format bc` renders within a small FLIP of the same floor compiled
//! with `rgba8`; passes that read textures as RGBA8 words refuse the BC file by name.

use kiln_compiler::ir::TextureRole;
use kiln_compiler::settings::{Settings, TextureFormat};
use kiln_format::manifest::LightKind;
use kiln_format::sections::{self, PixelFormat};
use kiln_format::{Checksums, KilnFile, SceneView};
use kiln_player::render::TexelDecode;
use kiln_test_support::gpu_test;
use kiln_tests::{GBuffer, Options, compile, scene_of};

use crate::harness::{H, Pinhole, W, fast_settings, light, render, square, square_uvs, texture};

fn textured_floor(format: TextureFormat) -> Vec<u8> {
    let mut scene = scene_of(&square(0.0, 10.0));
    // UVs over the floor: the square's corners map to [0, 2]² (the textures repeat); sizes that
    // leave partial blocks at the right and bottom of every level.
    square_uvs(&mut scene, 2.0);
    let unorm = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    scene.textures = vec![
        texture("albedo", 37, 29, TextureRole::Color, |u, v| {
            let check = if ((u * 6.0) as i32 + (v * 5.0) as i32) % 2 == 0 { 0.9 } else { 0.4 };
            [unorm(check * u), unorm(0.3 + 0.5 * v), unorm(check), unorm(0.6 + 0.4 * u)]
        }),
        texture("metal-rough", 22, 18, TextureRole::Data, |u, v| [0, unorm(0.3 + 0.6 * u), unorm(v), 255]),
        texture("normals", 19, 23, TextureRole::Normal, |u, v| {
            let (x, y) = (0.3 * (u * 12.0).sin(), 0.3 * (v * 9.0).cos());
            let z = (1.0 - x * x - y * y).sqrt();
            [unorm(x * 0.5 + 0.5), unorm(y * 0.5 + 0.5), unorm(z * 0.5 + 0.5), 255]
        }),
    ];
    let m = &mut scene.materials[0].gpu;
    m.base_color_texture = 0;
    m.metallic_roughness_texture = 1;
    m.normal_texture = 2;
    m.metallic = 1.0;
    m.roughness = 1.0;
    m.flags &= !sections::MaterialFlags::DIFFUSE_ONLY;
    scene.lights.push(light(LightKind::Point, [2.0, 4.0, -1.0], [0.0, -1.0, 0.0], 30.0));
    scene
        .cameras
        .push(Pinhole::new([0.0, 7.0, 6.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 60.0, W, H).file_camera());
    compile(scene, Settings { texture_format: format, ..fast_settings() })
}

#[test]
fn bc_textures_render_within_a_small_flip_of_rgba8() {
    let dir = gpu_test!();
    let bc = textured_floor(TextureFormat::Bc);
    let rgba8 = textured_floor(TextureFormat::Rgba8);
    // The files hold what the names say: BC7, BC5 (two uses) and RGBA8.
    let formats = |bytes: &[u8]| -> Vec<PixelFormat> {
        let f = KilnFile::from_bytes(bytes, Checksums::Eager).unwrap();
        let v = SceneView::new(&f).unwrap();
        (0..v.manifest.textures.len()).map(|i| v.texture(i).unwrap().format).collect()
    };
    assert_eq!(formats(&bc), [PixelFormat::Bc7, PixelFormat::Bc5, PixelFormat::Bc5]);
    assert_eq!(formats(&rgba8), [PixelFormat::Rgba8; 3]);
    let (a, _) = render(dir.path(), "floor-rgba8", &rgba8, |f| Options::new(f, W, H));
    let (b, _) = render(dir.path(), "floor-bc", &bc, |f| Options::new(f, W, H));
    let tone = |v: &[f32]| -> Vec<f32> { v.iter().map(|&x| x / (1.0 + x)).collect() };
    let (ta, tb) = (tone(&a), tone(&b));
    fn img(p: &[f32]) -> kiln_metrics::RgbImage<'_> {
        kiln_metrics::RgbImage { width: W, height: H, pixels: p }
    }
    let flip = kiln_metrics::ldr_flip(img(&ta), img(&tb)).unwrap();
    let lit = a.chunks_exact(3).filter(|p| p.iter().sum::<f32>() > 0.01).count();
    eprintln!("textured floor: mean FLIP {flip:.4} between the BC and RGBA8 files, {lit} lit pixels");
    assert!(lit > (W * H / 3) as usize, "only {lit} lit pixels");
    // Encoding error alone is under 0.01 mean FLIP on these textures; a wrong swizzle (roughness
    // read from the wrong channel) or a lost normal z moves the floor by far more.
    assert!(flip < 0.02, "mean FLIP {flip} between the BC and RGBA8 renders");

    // The visibility buffer's resolve decodes the blocks in GLSL from the texel buffer (the
    // raster pass samples them through the GPU's texture units): the two G-buffers agree on
    // the BC file as closely as they do on the RGBA8 file.
    let (c, bc_vis) =
        render(dir.path(), "floor-bc-vis", &bc, |f| Options::new(f, W, H).gbuffer(GBuffer::Visibility));
    let (d, rgba8_vis) =
        render(dir.path(), "floor-rgba8-vis", &rgba8, |f| Options::new(f, W, H).gbuffer(GBuffer::Visibility));
    // The resolve's pipeline has the decoders only for the file that needs them (the RGBA8
    // file's would compile as slowly as the BC file's, the regression this checks without
    // timing it).
    assert_eq!(bc_vis.session.renderer.texel_decode(), TexelDecode::Bc);
    assert_eq!(rgba8_vis.session.renderer.texel_decode(), TexelDecode::Rgba8);
    let (tc, td) = (tone(&c), tone(&d));
    let gbuffers_rgba8 = kiln_metrics::ldr_flip(img(&ta), img(&td)).unwrap();
    let gbuffers_bc = kiln_metrics::ldr_flip(img(&tb), img(&tc)).unwrap();
    let vis = kiln_metrics::ldr_flip(img(&td), img(&tc)).unwrap();
    eprintln!(
        "raster vs visibility G-buffer: mean FLIP {gbuffers_rgba8:.4} (RGBA8), {gbuffers_bc:.4} (BC); \
         visibility BC vs RGBA8 {vis:.4}"
    );
    assert!(
        gbuffers_bc < gbuffers_rgba8 + 0.005,
        "BC decoded in GLSL differs from the sampler's: {gbuffers_bc}"
    );
    assert!(vis < 0.02, "mean FLIP {vis} between the BC and RGBA8 visibility-buffer renders");
}

/// The reference path tracer filters the materials' textures stochastically (one texel of the
/// bilinear footprint per lookup, chosen by its weight): its mean must be the bilinear filter's.
/// A white furnace: a Lambertian floor under a sky of radiance 1 sees only the sky, so each
/// sample returns exactly the albedo its lookup read, and the pixel the mean albedo over its
/// samples. The floor's base colour is a ramp of four texels across u (0, ⅓, ⅔, 1; linear
/// values, sRGB-encoded) magnified to 5 units a texel, whose bilinear value at each pixel's
/// floor point the test computes itself: mean error 0.0188 at 32 samples a pixel (the choice's
/// noise), against 0.1641 when planted, the corner chosen with the complementary probability
/// (the ramp interpolated backwards within each texel pair).
#[test]
fn the_reference_filters_textures_bilinearly_on_average() {
    use std::time::Instant;

    use kiln_format::manifest::Sky;

    use crate::harness::{floor_pixels, srgb8};

    let dir = gpu_test!();
    let cam = Pinhole::new([0.0, 6.0, 9.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 60.0, W, H);
    let mut scene = scene_of(&square(0.0, 10.0));
    square_uvs(&mut scene, 1.0);
    const N: u32 = 4;
    // sRGB codes whose linear values are near 0, ⅓, ⅔ and 1; the test uses their exact decoding.
    const CODES: [u8; 4] = [0, 156, 213, 255];
    let ramp = |i: i64| srgb8(CODES[i.rem_euclid(N as i64) as usize]) as f64;
    scene.textures = vec![texture("ramp", N, N, TextureRole::Color, |u, _| {
        let c = CODES[(u * N as f32) as usize];
        [c, c, c, 255]
    })];
    let m = &mut scene.materials[0].gpu;
    m.base_color = [1.0; 4];
    m.base_color_texture = 0;
    scene.sky = Sky { radiance: [1.0; 3] };
    scene.cameras.push(cam.file_camera());
    let file = dir.path().join("ramp.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    let o = Options::new(&file, W, H).unshadowed().reference().build();
    let (_, rgb) = kiln_player::reference::render(&o, 32, Instant::now()).expect("reference render");
    // The bilinear filter at floor point p: texel centres at (i + ½) / N, repeating.
    let bilinear = |p: glam::DVec3| {
        let x = (p.x + 10.0) / 20.0 * N as f64 - 0.5;
        let i = x.floor() as i64;
        let fx = x - i as f64;
        ramp(i) * (1.0 - fx) + ramp(i + 1) * fx
    };
    let pixels: Vec<_> = floor_pixels(&cam, 9.5).into_iter().filter(|&(_, p, _)| p.z > 0.0).collect();
    assert!(pixels.len() > 500, "only {} pixels", pixels.len());
    let error = pixels.iter().map(|&(i, p, _)| (rgb[i] as f64 - bilinear(p)).abs()).sum::<f64>()
        / pixels.len() as f64;
    eprintln!("{} pixels, mean |reference − bilinear| {error:.4}", pixels.len());
    assert!(error < 0.04, "the reference's texture lookups average {error} away from the bilinear filter");
}

/// The reference path tracer decodes block-compressed textures once, at upload, into an RGBA8
/// texel buffer (no BC decoder in its shader). Its image of the BC floor must then be the image
/// of the same floor compiled RGBA8 (no block anywhere), but for the encoding error: the same
/// random sequence makes the two differ only where a texel does.
#[test]
fn the_reference_renders_bc_textures_as_their_rgba8_originals() {
    use std::time::Instant;
    let dir = gpu_test!();
    let mut images = Vec::new();
    for (name, format) in [("bc", TextureFormat::Bc), ("rgba8", TextureFormat::Rgba8)] {
        let file = dir.path().join(format!("floor-{name}.kiln"));
        std::fs::write(&file, textured_floor(format)).unwrap();
        let o = Options::new(&file, W, H).reference().build();
        images.push(kiln_player::reference::render(&o, 16, Instant::now()).expect("reference render").1);
    }
    let tone = |v: &[f32]| -> Vec<f32> { v.iter().map(|&x| x / (1.0 + x)).collect() };
    let (a, b) = (tone(&images[0]), tone(&images[1]));
    let img = |p| kiln_metrics::RgbImage { width: W, height: H, pixels: p };
    let flip = kiln_metrics::ldr_flip(img(&a), img(&b)).unwrap();
    let lit = images[1].chunks_exact(3).filter(|p| p.iter().sum::<f32>() > 0.01).count();
    eprintln!(
        "reference of the textured floor: mean FLIP {flip:.4} between the BC and RGBA8 files, {lit} lit pixels"
    );
    assert!(lit > (W * H / 3) as usize, "only {lit} lit pixels");
    assert!(flip < 0.02, "mean FLIP {flip} between the references of the BC and RGBA8 files");
}
