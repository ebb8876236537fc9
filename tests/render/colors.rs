//! Vertex colours multiply the base colour in every path that shades a surface: a floor whose
//! colours vary linearly across it (so that interpolation over its triangles reproduces the
//! linear function exactly) against the closed form with that colour, per pixel.

use std::time::Instant;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::{LightKind, Sky};
use kiln_test_support::gpu_test;
use kiln_tests::{GBuffer, Options, compile, scene_of};

use crate::harness::{
    H, Pinhole, TOLERANCE, W, compare_plane, fast_settings, floor_pixels, light, render, square,
};

/// The floor's colour at `p`: red rises along x, blue falls along z, green is constant.
fn color_at(p: DVec3) -> [f64; 3] {
    [0.3 + 0.6 * (p.x + 10.0) / 20.0, 0.5, 0.9 - 0.5 * (p.z + 10.0) / 20.0]
}

/// A 20 × 20 floor of white Lambertian material coloured by [`color_at`] at its corners.
fn coloured_floor() -> kiln_compiler::ir::Scene {
    let mut scene = scene_of(&square(0.0, 10.0));
    scene.materials[0].gpu = lambert_material([1.0; 3]);
    let colors = scene
        .vertices
        .iter()
        .map(|v| {
            let c = color_at(Vec3::from(v.position).as_dvec3());
            [c[0], c[1], c[2], 1.0].map(|x| (x * 65535.0).round() as u16)
        })
        .collect();
    scene.set_colors(0, Some(colors));
    scene
}

#[test]
fn vertex_colours_multiply_the_base_colour_in_both_g_buffers() {
    let dir = gpu_test!();
    let cam = Pinhole::new([0.0, 8.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 60.0, W, H);
    let mut scene = coloured_floor();
    let lp = [1.0f32, 3.0, -0.5];
    let intensity = 10.0;
    scene.lights.push(light(LightKind::Point, lp, [0.0, -1.0, 0.0], intensity));
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let l = DVec3::from_array(lp.map(f64::from));
    for mode in [GBuffer::Raster, GBuffer::Visibility] {
        let (rgb, _) =
            render(dir.path(), &format!("colors-{mode:?}"), &bytes, |f| Options::new(f, W, H).gbuffer(mode));
        let n = compare_plane(
            &rgb,
            &cam,
            9.5,
            |_, _| true,
            |p| {
                let to = l - p;
                let d2 = to.length_squared();
                let cos = to.y / d2.sqrt();
                color_at(p).map(|k| k / std::f64::consts::PI * intensity as f64 * cos / d2)
            },
            // The albedo target is 8-bit sRGB: the colours here are not sRGB codes, so they round
            // by up to half a code (≤ 0.6 % at the darkest, 0.3).
            TOLERANCE + 0.006,
        );
        assert!(n > (W * H / 2) as usize, "{mode:?}: only {n} pixels compared");
    }
}

#[test]
fn the_reference_path_tracer_reads_vertex_colours() {
    let dir = gpu_test!();
    // A white furnace: a Lambertian floor under a sky of radiance 1 sees only the sky, so it
    // reflects exactly its albedo, here the vertex colour (cosine-weighted sampling has zero
    // variance there).
    let cam = Pinhole::new([0.0, 6.0, 9.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 60.0, W, H);
    let mut scene = coloured_floor();
    scene.sky = Sky { radiance: [1.0; 3] };
    scene.cameras.push(cam.file_camera());
    let file = dir.path().join("furnace.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    let o = Options::new(&file, W, H).unshadowed().reference().build();
    let (_, rgb) = kiln_player::reference::render(&o, 8, Instant::now()).expect("reference render");
    // Near the camera, where a pixel's footprint (over which its samples spread) is small.
    let pixels: Vec<_> = floor_pixels(&cam, 9.5).into_iter().filter(|&(_, p, _)| p.z > 0.0).collect();
    assert!(pixels.len() > 500, "only {} pixels", pixels.len());
    let mut worst = 0.0f64;
    for &(i, p, _) in &pixels {
        let e = color_at(p);
        for c in 0..3 {
            let rel = (rgb[i + c] as f64 - e[c]).abs() / e[c];
            worst = worst.max(rel);
        }
    }
    eprintln!("{} pixels, worst relative error {:.4}%", pixels.len(), worst * 100.0);
    assert!(worst < 0.01, "worst relative error {worst} against the vertex colour");
}
