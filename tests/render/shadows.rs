//! A square occluder over a floor under a point light: the umbra its geometry implies is black,
//! the floor outside it lit as if unoccluded, from shadow maps and from ray-traced shadows.

use std::path::Path;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_compiler::settings::{Settings, VoxelRes};
use kiln_format::linespace::Variants;
use kiln_format::manifest::LightKind;
use kiln_test_support::{gpu_test, require, vulkan};
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{
    ALBEDO, H, Pinhole, TOLERANCE, W, albedo, compare_plane, fast_settings, floor_pixels, light, pixel_xy,
    render, square, srgb8,
};

#[test]
fn an_occluder_casts_the_shadow_its_geometry_implies() {
    require!(vulkan());
    // Shadow maps: PCF blurs the edge over a few texels.
    occluder_case("occluder", [0.15; 2], fast_settings(), |f| Options::new(f, W, H));
}

#[test]
fn ray_traced_hard_shadows_are_exact_up_to_the_pixel_at_the_umbra_edge() {
    require!(vulkan());
    // A point light of radius 0: one ray per pixel decides exactly, so only pixels whose
    // footprint straddles the edge (about 0.06 units here) are left out.
    occluder_case("occluder-rt", [0.04; 2], fast_settings(), |f| Options::new(f, W, H).rt_shadows(0.0, 0.0));
}

/// The compile settings of the line-space cases: a coarse grid (6 cells on the floor's side) so
/// that most feelers cross cells beyond the exact reach of their ends.
pub(crate) fn line_space_settings() -> Settings {
    Settings {
        shaft_variants: Some(Variants::BINARY),
        voxel_res: VoxelRes::Cells(6),
        shaft_res: Some(4),
        ..fast_settings()
    }
}

#[test]
fn line_space_shadow_feelers_exact_in_filled_shafts_equal_ray_traced_shadows() {
    require!(vulkan());
    occluder_case("occluder-ls-filled", [0.04; 2], line_space_settings(), |f| {
        Options::new(f, W, H).line_space_shadows(true)
    });
}

#[test]
fn line_space_shadow_feelers_darken_the_umbra_and_only_what_the_shafts_cover() {
    require!(vulkan());
    // Conservative between the ends: the umbra is exact and black; the lit floor may be darkened
    // only within the shafts around the occluder, which at 6 cells and N = 4 reach at most one
    // floor cell (10 / 6 units) beyond the umbra's edge.
    occluder_case("occluder-ls-ends", [0.04, 10.0 / 6.0], line_space_settings(), |f| {
        Options::new(f, W, H).line_space_shadows(false)
    });
}

#[test]
fn line_space_shadows_refuse_a_file_without_line_space() {
    let dir = gpu_test!();
    let bytes = compile(scene_of(&square(0.0, 1.0)), fast_settings());
    let file = dir.path().join("plain.kiln");
    std::fs::write(&file, bytes).unwrap();
    let e = kiln_player::session::Session::open(
        &Options::new(&file, 8, 8).line_space_shadows(false).build(),
        std::time::Instant::now(),
    )
    .unwrap_err();
    assert!(e.message.contains("--shaft-variants binary"), "{}", e.message);
}

/// `margins`: how far inside the umbra's edge pixels must be black, and how far outside it they
/// must be fully lit (the filters' or the shafts' reach).
fn occluder_case(name: &str, margins: [f64; 2], settings: Settings, shadowed: impl Fn(&Path) -> Options) {
    let [inner, outer] = margins;
    let dir = tempfile::tempdir().unwrap();
    // A 2 × 2 square at height 1 under a point light at height 4: its umbra on the floor is the
    // square scaled by 4 / (4 − 1), |x|, |z| < 4/3.
    let cam = Pinhole::new([5.0, 9.0, 6.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 45.0, W, H);
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 10.0).to_vec();
    tris.extend(square(1.0, 1.0));
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = lambert_material(ALBEDO.map(srgb8));
    let lp = [0.0f32, 4.0, 0.0];
    let intensity = 20.0;
    scene.lights.push(light(LightKind::Point, lp, [0.0, -1.0, 0.0], intensity));
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, settings);
    let (rgb, _) = render(dir.path(), name, &bytes, shadowed);
    let a = albedo();
    let l = DVec3::from_array(lp.map(f64::from));
    let edge = 4.0 / 3.0;
    // Pixels whose view of the floor the occluder hides are skipped.
    let visible = |p: DVec3, d: DVec3| {
        let t = (1.0 - cam.eye.y) / d.y;
        let q = cam.eye + d * t;
        let _ = p;
        !(q.x.abs() <= 1.05 && q.z.abs() <= 1.05)
    };
    let lit = |p: DVec3| {
        let to = l - p;
        let d2 = to.length_squared();
        a.map(|k| k / std::f64::consts::PI * intensity as f64 * (to.y / d2.sqrt()) / d2)
    };
    // Outside the umbra (beyond the PCF footprint) the floor is fully lit...
    let outside =
        |p: DVec3, d: DVec3| visible(p, d) && (p.x.abs() > edge + outer || p.z.abs() > edge + outer);
    let n_lit = compare_plane(&rgb, &cam, 6.0, outside, lit, TOLERANCE);
    // ...and inside it, black.
    let inside = |p: DVec3, d: DVec3| visible(p, d) && p.x.abs() < edge - inner && p.z.abs() < edge - inner;
    let mut n_dark = 0;
    for (i, p, d) in floor_pixels(&cam, edge) {
        if inside(p, d) {
            let (x, y) = pixel_xy(i);
            let unshadowed = lit(p);
            for c in 0..3 {
                assert!(
                    (rgb[i + c] as f64) < 1e-3 * unshadowed[c],
                    "pixel ({x}, {y}) at {p} should be in the umbra: {}",
                    rgb[i + c]
                );
            }
            n_dark += 1;
        }
    }
    eprintln!("{n_lit} lit and {n_dark} shadowed floor pixels checked");
    assert!(
        n_lit > 500 && n_dark > 30,
        "{n_lit} lit, {n_dark} shadowed pixels: the view does not test the shadow"
    );

    // With --shadows none the umbra is lit like the rest.
    let (unshadowed, _) = render(dir.path(), "occluder-none", &bytes, |f| Options::new(f, W, H).unshadowed());
    let n = compare_plane(&unshadowed, &cam, 6.0, inside, lit, TOLERANCE);
    assert!(n == n_dark);
}
