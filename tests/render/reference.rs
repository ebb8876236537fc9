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
    let rho = 0.5f64;
    let file = glowing_box(dir.path(), rho);
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

/// A closed box, the cube [-1, 1]³, whose walls all emit 1 and reflect diffusely with albedo
/// `rho`, seen from inside; written to `dir`.
fn glowing_box(dir: &std::path::Path, rho: f64) -> std::path::PathBuf {
    let emission = 1.0f32;
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
    let file = dir.join("glowing-box.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    file
}

#[test]
fn reference_samples_taken_in_one_dispatch_are_independent() {
    let dir = gpu_test!();
    // The path tracer takes several samples per pixel in one dispatch, starting the next as a
    // path ends. The mean of N independent samples has 1/N of their variance: between two
    // 16-sample images of different seeds, the squared differences must be 1/16 of those
    // between two one-sample images. A sample repeated, or drawn from its predecessor's
    // sequence, within a dispatch would leave more. Inside the glowing box every path ends by
    // Russian roulette after a random number of bounces, so the invocations of one dispatch
    // regenerate at different times.
    let file = glowing_box(dir.path(), 0.5);
    let o = Options::new(&file, W, H).reference().build();
    let render = |spp: u32, seed: u32| {
        let sampling =
            kiln_player::reference::Sampling { seed, ..kiln_player::reference::Sampling::new(spp) };
        kiln_player::reference::render_with(&o, sampling, Instant::now()).expect("reference render").1
    };
    let variance = |a: &[f32], b: &[f32]| {
        a.iter().zip(b).map(|(&x, &y)| (x as f64 - y as f64).powi(2)).sum::<f64>() / (2.0 * a.len() as f64)
    };
    // Paths of random length make the one-sample variance heavy-tailed: it is averaged over
    // four pairs of images.
    let one = (0..4).map(|k| variance(&render(1, 2 * k + 11), &render(1, 2 * k + 12))).sum::<f64>() / 4.0;
    let sixteen = variance(&render(16, 21), &render(16, 22));
    let ratio = one / sixteen;
    eprintln!(
        "per-pixel variance: 1 sample {one:.5}, 16 samples {sixteen:.6}, ratio {ratio:.2} (expected 16)"
    );
    assert!(one > 0.01, "the one-sample images barely differ ({one}): the test sees no noise");
    assert!((12.0..21.0).contains(&ratio), "16 samples reduce the variance {ratio:.2}×, not 16×");
}

#[test]
fn reference_path_tracer_sees_through_blended_and_transmitting_surfaces() {
    let dir = gpu_test!();
    // An emitter of radiance 1 behind two panes, the sky black:
    // - left, a black alpha-blended pane of alpha a: rays meet it with probability a (stochastic
    //   coverage) and reach the emitter otherwise, so the pixels behind it see 1 − a;
    // - right, a smooth thin glass of base colour c transmitting all of its diffuse light
    //   (KHR_materials_transmission): light passes unbent, tinted, less what the glass reflects,
    //   so the pixels behind it see (1 − F) c per channel, F the Schlick Fresnel of F0 0.04 at
    //   the view angle (below 15° here: F = 0.04 to 1e-7), while what it reflects towards the
    //   camera is the black sky.
    // The pixels beside the panes see the emitter, 1.
    let a = 0.3f32;
    let c = [0.9f32, 0.5, 0.25];
    let rect = |z: f32, x0: f32, x1: f32, h: f32| {
        let p = |x: f32, y: f32| Vec3::new(x, y, z);
        [[p(x0, -h), p(x1, -h), p(x1, h)], [p(x0, -h), p(x1, h), p(x0, h)]]
    };
    let mut tris = rect(-2.0, -4.0, 4.0, 4.0).to_vec();
    tris.extend(rect(-1.0, -0.9, -0.1, 0.5));
    tris.extend(rect(-1.0, 0.1, 0.9, 0.5));
    let mut scene = scene_of(&tris);
    let mut emitter = kiln_compiler::import::demo::lambert_material([0.0; 3]);
    emitter.emission = [1.0; 3];
    let mut pane = kiln_compiler::import::demo::lambert_material([0.0; 3]);
    pane.base_color[3] = a;
    pane.flags |= (kiln_format::sections::AlphaMode::Blend as u32)
        << kiln_format::sections::MaterialFlags::ALPHA_MODE_SHIFT;
    let glass = kiln_format::sections::GpuMaterial {
        base_color: [c[0], c[1], c[2], 1.0],
        metallic: 0.0,
        roughness: 0.0,
        transmission: 1.0,
        ..Default::default()
    };
    scene.materials = vec![
        kiln_compiler::ir::Material { name: "emitter".into(), gpu: emitter },
        kiln_compiler::ir::Material { name: "pane".into(), gpu: pane },
        kiln_compiler::ir::Material { name: "glass".into(), gpu: glass },
    ];
    scene.triangle_materials = vec![0, 0, 1, 1, 2, 2];
    scene.sky = Sky { radiance: [0.0; 3] };
    let cam = Pinhole::new([0.0, 0.0, 2.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 40.0, W, H);
    scene.cameras.push(cam.file_camera());
    let file = dir.path().join("pane.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    let o = Options::new(&file, W, H).reference().build();
    let (_, rgb) = kiln_player::reference::render(&o, 256, Instant::now()).expect("reference render");
    // Pixels whose ray crosses z = −1 well inside a pane, and well outside both; the glass's
    // expected value per pixel from its view angle.
    let (mut inside, mut glass, mut outside) = (Vec::new(), Vec::new(), Vec::new());
    for y in 0..H {
        for x in 0..W {
            let d = cam.ray(x, y, W, H);
            let q = DVec3::new(0.0, 0.0, 2.0) + d * (3.0 / -d.z);
            let i = 3 * (y * W + x) as usize;
            let within = |x0: f64, x1: f64| q.x > x0 + 0.1 && q.x < x1 - 0.1 && q.y.abs() < 0.4;
            if within(-0.9, -0.1) {
                inside.push(rgb[i] as f64);
            } else if within(0.1, 0.9) {
                let cos = -d.normalize().z;
                let f = 0.04 + 0.96 * (1.0 - cos).powi(5);
                for k in 0..3 {
                    glass.push((rgb[i + k] as f64, (1.0 - f) * c[k] as f64));
                }
            } else if q.x.abs() > 1.0 || q.y.abs() > 0.6 {
                outside.push(rgb[i] as f64);
            }
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (mi, mo) = (mean(&inside), mean(&outside));
    let got: f64 = glass.iter().map(|g| g.0).sum();
    let expected: f64 = glass.iter().map(|g| g.1).sum();
    let by_channel = |k: usize| {
        let (g, e) = glass.iter().skip(k).step_by(3).fold((0.0, 0.0), |(g, e), p| (g + p.0, e + p.1));
        g / e
    };
    eprintln!(
        "behind the pane {mi:.4} ({} pixels), behind the glass {:.4} of (1 − F) c (RGB {:.4} {:.4} {:.4}; {} pixels), beside {mo:.4} ({} pixels)",
        inside.len(),
        got / expected,
        by_channel(0),
        by_channel(1),
        by_channel(2),
        glass.len() / 3,
        outside.len()
    );
    assert!(inside.len() > 100 && glass.len() > 300 && outside.len() > 300);
    assert!((mo - 1.0).abs() < 0.01, "the emitter seen directly: {mo}");
    assert!((mi - (1.0 - a as f64)).abs() < 0.02, "behind a pane of alpha {a}: {mi}, expected {}", 1.0 - a);
    for k in 0..3 {
        assert!(
            (by_channel(k) - 1.0).abs() < 0.02,
            "behind the glass, channel {k}: {} of (1 − F) c",
            by_channel(k)
        );
    }
}
