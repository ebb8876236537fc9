//! Whole scenes with the validation layer on: the demo Cornell box (PNG and EXR, a camera
//! override) and PICA PICA (three lights, textures, both G-buffers, the hybrid pipeline).

use std::path::PathBuf;
use std::time::Instant;

use kiln_compiler::import::demo::cornell_box;
use kiln_compiler::settings::Settings;
use kiln_player::camera::CameraOverride;
use kiln_player::headless;
use kiln_test_support::gpu_test;
use kiln_tests::{GBuffer, Options, Reflections, compile, shared_scenes};

use crate::harness::{fast_settings, render, render_frames};

#[test]
fn demo_scene_renders_clean_in_png_and_exr_with_a_camera_override() {
    let dir = gpu_test!();
    let bytes = compile(cornell_box(), fast_settings());
    let (rgb, result) = render(dir.path(), "demo", &bytes, |f| Options::new(f, 64, 48));
    assert!(rgb.iter().any(|&v| v > 0.0), "the demo frame is black");
    assert!(result.session.times.first_frame_since_start_ms > 0.0);
    drop(result);
    // PNG through the same path, and a camera override that looks away from the box (sky only).
    let file = dir.path().join("demo.kiln");
    let png = dir.path().join("demo.png");
    headless::run(&Options::new(&file, 64, 48).build(), 2, Some(&png), Instant::now()).unwrap();
    let img = image::open(&png).unwrap().into_rgb8();
    assert_eq!(img.dimensions(), (64, 48));
    let away: CameraOverride = "0,1,3.9,0,1,100,40".parse().unwrap();
    let (sky, _) = render(dir.path(), "demo", &bytes, |f| Options::new(f, 16, 16).camera(away));
    assert!(sky.iter().all(|&v| v == 0.0), "looking away from the box should see the black sky");
}

#[test]
fn pica_pica_renders_clean_with_three_lights_and_its_shadow_maps() {
    let dir = gpu_test!();
    let Some(scenes) = shared_scenes() else {
        return;
    };
    let mut inputs = Vec::new();
    let mut scene = kiln_compiler::import::import(&scenes.join("pica_pica/scene.gltf")).unwrap();
    let side = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/pica_pica.toml");
    kiln_compiler::import::sidecar::Sidecar::load(&side, &mut inputs)
        .unwrap()
        .apply(&mut scene, "pica_pica.toml")
        .unwrap();
    let bytes = compile(scene, Settings { shaft_variants: Some(0), shadow_res: 256, ..Default::default() });
    let (rgb, result) = render(dir.path(), "pica", &bytes, |f| Options::new(f, 160, 90));
    let s = &result.session;
    assert_eq!(s.scene.manifest.lights.len(), 3);
    assert_eq!(s.scene.shadow_maps.len(), 3, "every light's shadow map is resident");
    assert_eq!(s.scene.textures.len(), s.scene.manifest.textures.len());
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let lit = rgb.chunks_exact(3).filter(|p| p.iter().sum::<f32>() > 0.05).count();
    assert!(lit > rgb.len() / 3 / 4, "only {lit} pixels are lit");

    // The visibility buffer resolved in compute (trilinear filtering from the texel buffer's mip
    // chains, normal maps through ray differentials) gives the rasterised frame.
    let (vis, _) =
        render(dir.path(), "pica-vis", &bytes, |f| Options::new(f, 160, 90).gbuffer(GBuffer::Visibility));
    let close = rgb.iter().zip(&vis).filter(|(a, b)| (*a - *b).abs() <= 0.02 * a.abs().max(0.01)).count();
    eprintln!(
        "pica_pica: {:.2} % of channels within 2 % between raster and visibility G-buffers",
        100.0 * close as f64 / rgb.len() as f64
    );
    assert!(close as f64 >= 0.98 * rgb.len() as f64, "{close} of {} channels agree", rgb.len());

    // The hybrid pipeline: every ray-traced pass, both reflection resolutions and both
    // G-buffers, validation clean (render asserts it), finite, and close to the shadow-mapped
    // frame on average.
    for (res, gbuffer) in [(Reflections::Full, GBuffer::Raster), (Reflections::Half, GBuffer::Visibility)] {
        let (traced, result) = render_frames(dir.path(), "pica-rt", &bytes, 2, |f| {
            Options::new(f, 160, 90).rt_shadows(0.05, 0.53).rt_ao(None).rt_reflections(res).gbuffer(gbuffer)
        });
        assert!(result.session.warnings.is_empty(), "{:?}", result.session.warnings);
        let mean = |v: &[f32]| v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
        let (a, b) = (mean(&rgb), mean(&traced));
        eprintln!("pica_pica mean radiance: shadow maps {a:.4}, ray traced ({res:?}) {b:.4}");
        assert!((b / a - 1.0).abs() < 0.25, "{res:?}: mean radiance {b} vs {a} with shadow maps");
    }
}
