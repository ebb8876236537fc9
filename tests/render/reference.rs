//! The reference path tracer in a white furnace: rough metal under a uniform sky reflects the
//! GGX directional albedo the compiler integrates independently.

use std::time::Instant;

use glam::{DVec3, Vec3};
use kiln_format::manifest::Sky;
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{H, Pinhole, W, fast_settings, floor_pixels, metal, ratio_stats};

#[test]
fn reference_path_tracer_reflects_a_uniform_sky_off_rough_metal_with_the_ggx_albedo() {
    let dir = gpu_test!();
    // A white-furnace check of the reference path tracer's GGX: a metal floor with F0 = 1 in a
    // sky of radiance 1 reflects exactly the directional albedo E(n·v, roughness) of
    // single-scattering GGX with height-correlated Smith (a half-space sees only the sky, so one
    // bounce is the whole answer). E comes from the compiler's independent quadrature of the
    // same BRDF (`brdf_lut::integrate`, checked against Gauss–Legendre at 1e-3), so the sampling
    // (visible normals), the evaluation and their MIS weights must agree for the mean to match.
    let roughness = [0.2f32, 0.5, 1.0];
    let cam = Pinhole::new([0.0, 6.0, 9.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 60.0, W, H);
    let strip = |x0: f32, x1: f32| {
        let p = |x: f32, z: f32| Vec3::new(x, 0.0, z);
        [[p(x0, -20.0), p(x0, 20.0), p(x1, 20.0)], [p(x0, -20.0), p(x1, 20.0), p(x1, -20.0)]]
    };
    let bounds = [(-30.0f32, -1.0f32), (-1.0, 1.0), (1.0, 30.0)];
    let mut tris = Vec::new();
    for &(x0, x1) in &bounds {
        tris.extend(strip(x0, x1));
    }
    let mut scene = scene_of(&tris);
    scene.materials.clear();
    for (i, &r) in roughness.iter().enumerate() {
        scene.materials.push(kiln_compiler::ir::Material { name: format!("metal {r}"), gpu: metal(1.0, r) });
        scene.triangle_materials[2 * i..2 * i + 2].fill(i as u32);
    }
    scene.sky = Sky { radiance: [1.0; 3] };
    scene.cameras.push(cam.file_camera());
    let file = dir.path().join("furnace.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    let o = Options::new(&file, W, H).unshadowed().reference().build();
    let (_, rgb) = kiln_player::reference::render(&o, 64, Instant::now()).expect("reference render");
    for (k, &r) in roughness.iter().enumerate() {
        let (x0, x1) = bounds[k];
        // Pixels well inside the strip (the pixel footprint never crosses its edges).
        let pixels: Vec<_> = floor_pixels(&cam, 19.0)
            .into_iter()
            .filter(|&(_, p, _)| p.x > x0 as f64 + 0.2 && p.x < x1 as f64 - 0.2)
            .collect();
        let expected = |_: DVec3, d: DVec3| {
            let (rr, gg) = kiln_compiler::bake::brdf_lut::integrate(-d.normalize().y, r as f64);
            rr + gg
        };
        let (mean, spread) = ratio_stats(&rgb, &pixels, expected);
        eprintln!(
            "roughness {r}: {} pixels, mean ratio to E(n·v) {mean:.4} (spread {spread:.4})",
            pixels.len()
        );
        assert!(pixels.len() > 300, "roughness {r}: only {} pixels", pixels.len());
        assert!((mean - 1.0).abs() < 0.01, "roughness {r}: mean ratio {mean} to the GGX albedo");
    }
}

#[test]
fn reference_path_tracer_counts_exactly_the_bounces_it_is_limited_to() {
    let dir = gpu_test!();
    // Inside a closed box whose walls all emit Le and reflect diffusely with albedo ρ, every
    // point receives the same radiance, so the light after at most N scattering events is
    // Le (1 + ρ + … + ρ^N) everywhere, and Le / (1 − ρ) without a limit. The bounce limit that
    // kiln-bench uses for its direct-light and two-bounce references must give exactly these.
    let (emission, rho) = (1.0f32, 0.5f64);
    let mut tris = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            // A face of the cube [-1, 1]³ wound so that its normal points inwards.
            let mut n = Vec3::ZERO;
            n[axis] = -sign;
            let c = -n;
            let u = if axis == 0 { Vec3::Y } else { Vec3::X };
            let v = n.cross(u);
            let p = [c - u - v, c + u - v, c + u + v, c - u + v];
            tris.push([p[0], p[1], p[2]]);
            tris.push([p[0], p[2], p[3]]);
        }
    }
    let mut scene = scene_of(&tris);
    let mut m = kiln_compiler::import::demo::lambert_material([rho as f32; 3]);
    m.emission = [emission; 3];
    scene.materials[0].gpu = m;
    scene.sky = Sky { radiance: [0.0; 3] };
    let cam = Pinhole::new([0.0, 0.2, 0.5], [0.3, 0.0, -1.0], [0.0, 1.0, 0.0], 70.0, W, H);
    scene.cameras.push(cam.file_camera());
    let file = dir.path().join("glowing-box.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    let o = Options::new(&file, W, H).reference().build();
    for (bounces, expected) in [(1u32, 1.0 + rho), (2, 1.0 + rho + rho * rho), (0, 1.0 / (1.0 - rho))] {
        let sampling =
            kiln_player::reference::Sampling { bounces, ..kiln_player::reference::Sampling::new(64) };
        let (_, rgb) =
            kiln_player::reference::render_with(&o, sampling, Instant::now()).expect("reference render");
        let mean = rgb.iter().map(|&v| v as f64).sum::<f64>() / rgb.len() as f64;
        eprintln!("{bounces} bounces (0: all): mean {mean:.4}, expected {expected:.4}");
        assert!((mean / expected - 1.0).abs() < 0.01, "{bounces} bounces: mean {mean}, expected {expected}");
    }
}

#[test]
fn reference_path_tracer_sees_through_blended_surfaces_by_their_coverage() {
    let dir = gpu_test!();
    // An emitter of radiance 1 seen through a black, alpha-blended pane of alpha a: rays meet the
    // pane with probability a (stochastic coverage) and reach the emitter otherwise, so the
    // pixels behind the pane see 1 − a and the others 1 (the pane reflects nothing). Imported
    // glTF transmission is read as such coverage (KHR_materials_transmission).
    let a = 0.3f32;
    let quad = |z: f32, h: f32| {
        let p = |x: f32, y: f32| Vec3::new(x, y, z);
        [[p(-h, -h), p(h, -h), p(h, h)], [p(-h, -h), p(h, h), p(-h, h)]]
    };
    let mut tris = quad(-2.0, 4.0).to_vec();
    tris.extend(quad(-1.0, 0.5));
    let mut scene = scene_of(&tris);
    let mut emitter = kiln_compiler::import::demo::lambert_material([0.0; 3]);
    emitter.emission = [1.0; 3];
    let mut pane = kiln_compiler::import::demo::lambert_material([0.0; 3]);
    pane.base_color[3] = a;
    pane.flags |= (kiln_format::sections::AlphaMode::Blend as u32)
        << kiln_format::sections::MaterialFlags::ALPHA_MODE_SHIFT;
    scene.materials = vec![
        kiln_compiler::ir::Material { name: "emitter".into(), gpu: emitter },
        kiln_compiler::ir::Material { name: "pane".into(), gpu: pane },
    ];
    scene.triangle_materials = vec![0, 0, 1, 1];
    scene.sky = Sky { radiance: [0.0; 3] };
    let cam = Pinhole::new([0.0, 0.0, 2.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 40.0, W, H);
    scene.cameras.push(cam.file_camera());
    let file = dir.path().join("pane.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    let o = Options::new(&file, W, H).reference().build();
    let (_, rgb) = kiln_player::reference::render(&o, 256, Instant::now()).expect("reference render");
    // Pixels whose ray crosses z = −1 well inside the pane, and well outside it.
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for y in 0..H {
        for x in 0..W {
            let d = cam.ray(x, y, W, H);
            let q = DVec3::new(0.0, 0.0, 2.0) + d * (3.0 / -d.z);
            let r = q.x.abs().max(q.y.abs());
            let v = rgb[3 * (y * W + x) as usize] as f64;
            if r < 0.4 {
                inside.push(v);
            } else if r > 0.6 {
                outside.push(v);
            }
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (mi, mo) = (mean(&inside), mean(&outside));
    eprintln!(
        "behind the pane {mi:.4} ({} pixels), beside it {mo:.4} ({} pixels)",
        inside.len(),
        outside.len()
    );
    assert!(inside.len() > 300 && outside.len() > 300);
    assert!((mo - 1.0).abs() < 0.01, "the emitter seen directly: {mo}");
    assert!((mi - (1.0 - a as f64)).abs() < 0.02, "behind a pane of alpha {a}: {mi}, expected {}", 1.0 - a);
}
