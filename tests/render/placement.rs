//! One room, rendered where it is placed: at the origin, 10⁵ units out, and scaled by 10⁻³ and
//! 10³. Radiance does not depend on scale or position, so every placement must give the image of
//! the room at the origin, within noise. The room is written as OBJ text (the world-space digits a
//! far asset holds) and imported as `kiln compile` imports it; the camera is given in world space
//! through the player's `--camera` override.
//!
//! Before positions were stored relative to an origin near the scene, the reference frame of the
//! room 10⁵ units out was 47 % darker than at the origin: single precision there spaces floats
//! 8 mm apart, and the lamp hangs 1 cm below the ceiling.

use std::time::Instant;

use glam::DVec3;
use kiln_player::camera::CameraOverride;
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile};

use crate::harness::{fast_settings, render_frames};
use crate::media::mean;

const W: u32 = 32;
const H: u32 = 24;

/// The room in unit coordinates: an open-fronted box 2 wide, 2 high, 2 deep, a block inside
/// and a lamp 1 cm below the ceiling (as McGuire's Cornell box), as OBJ faces over `v` lines
/// placed at `scale · p + offset`, each facing where its normal says. Emission is radiance,
/// which no placement changes.
fn room_obj(scale: f64, offset: DVec3) -> (String, String) {
    let (lo, hi) = (DVec3::new(-0.5, 0.0, -0.5), DVec3::new(0.1, 0.6, 0.1));
    let mut quads: Vec<(&str, [DVec3; 4], DVec3)> = Vec::new();
    // Axis-aligned rectangle at `at` along axis `a`, spanning [u0, u1] × [v0, v1] on the others.
    let rect = |a: usize, at: f64, (u0, u1): (f64, f64), (v0, v1): (f64, f64)| {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        [(u0, v0), (u1, v0), (u1, v1), (u0, v1)].map(|(u, v)| {
            let mut p = DVec3::ZERO;
            p[a] = at;
            p[b] = u;
            p[c] = v;
            p
        })
    };
    let n = |a: usize, sign: f64| {
        let mut v = DVec3::ZERO;
        v[a] = sign;
        v
    };
    quads.push(("white", rect(1, 0.0, (-1.0, 1.0), (-1.0, 1.0)), n(1, 1.0)));
    quads.push(("white", rect(1, 2.0, (-1.0, 1.0), (-1.0, 1.0)), n(1, -1.0)));
    quads.push(("white", rect(2, -1.0, (-1.0, 1.0), (0.0, 2.0)), n(2, 1.0)));
    quads.push(("red", rect(0, -1.0, (0.0, 2.0), (-1.0, 1.0)), n(0, 1.0)));
    quads.push(("green", rect(0, 1.0, (0.0, 2.0), (-1.0, 1.0)), n(0, -1.0)));
    quads.push(("lamp", rect(1, 1.99, (-0.25, 0.25), (-0.25, 0.25)), n(1, -1.0)));
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for (at, sign) in [(lo[a], -1.0), (hi[a], 1.0)] {
            quads.push(("white", rect(a, at, (lo[b], hi[b]), (lo[c], hi[c])), n(a, sign)));
        }
    }
    let mut obj = String::from("mtllib room.mtl\n");
    for (k, (material, corners, facing)) in quads.iter().enumerate() {
        let mut corners = *corners;
        if (corners[1] - corners[0]).cross(corners[2] - corners[0]).dot(*facing) < 0.0 {
            corners.reverse();
        }
        for c in corners {
            let p = c * scale + offset;
            obj += &format!("v {:.9} {:.9} {:.9}\n", p.x, p.y, p.z);
        }
        let b = 4 * k + 1;
        obj += &format!("usemtl {material}\nf {} {} {} {}\n", b, b + 1, b + 2, b + 3);
    }
    let mtl = "newmtl white\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.6 0.05 0.05\nnewmtl green\nKd 0.1 0.5 0.1\n\
               newmtl lamp\nKd 0.7 0.7 0.7\nKe 12 12 12\n";
    (obj, mtl.to_string())
}

/// The room placed at `scale`, `offset` and compiled, and the camera in front of its open side,
/// looking in (world space).
fn room_file(
    dir: &std::path::Path,
    name: &str,
    scale: f64,
    offset: DVec3,
) -> (std::path::PathBuf, CameraOverride) {
    let (obj, mtl) = room_obj(scale, offset);
    let sub = dir.join(name);
    std::fs::create_dir_all(&sub).unwrap();
    std::fs::write(sub.join("room.obj"), obj).unwrap();
    std::fs::write(sub.join("room.mtl"), mtl).unwrap();
    let scene = kiln_compiler::import::import(&sub.join("room.obj")).unwrap();
    let file = sub.join("room.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    let at = |p: [f64; 3]| (DVec3::from(p) * scale + offset).to_array();
    let camera = CameraOverride {
        position: at([0.0, 1.0, 3.6]),
        target: at([0.0, 1.0, 0.0]),
        vfov_degrees: Some(40.0),
    };
    (file, camera)
}

/// How a test renders a room: the reference at `spp`, or `frames` frames of a technique.
#[derive(Clone, Copy)]
enum Render {
    Reference { spp: u32 },
    Frames { frames: u32, technique: fn(Options) -> Options },
}

fn render_room(dir: &std::path::Path, name: &str, scale: f64, offset: DVec3, how: Render) -> Vec<f32> {
    let (file, camera) = room_file(dir, name, scale, offset);
    let o = Options::new(&file, W, H).camera(camera);
    match how {
        Render::Reference { spp } => {
            kiln_player::reference::render(&o.reference().build(), spp, Instant::now())
                .expect("reference render")
                .1
        }
        Render::Frames { frames, technique } => {
            let bytes = std::fs::read(&file).unwrap();
            render_frames(file.parent().unwrap(), name, &bytes, frames, |f| {
                technique(Options::new(f, W, H).camera(camera))
            })
            .0
        }
    }
}

/// Relative mean squared error of `test` against `reference` (kiln-metrics': per channel,
/// (t − r)² / (r² + 10⁻²) averaged).
fn rel_mse(reference: &[f32], test: &[f32]) -> f64 {
    let img = |pixels| kiln_metrics::RgbImage { width: W, height: H, pixels };
    kiln_metrics::rel_mse(img(reference), img(test)).expect("images of one size")
}

/// Compares every placement's image with the origin's: means within `mean_tol` (relative), and
/// the per-pixel relMSE within `noise` (measured beside it: the origin's image against the
/// origin's image at another sample count is noise of the same order).
fn check_placements(name: &str, how: Render, mean_tol: f64, noise: f64) {
    let dir = gpu_test!();
    let origin = render_room(dir.path(), &format!("{name}-origin"), 1.0, DVec3::ZERO, how);
    let m0 = mean(&origin);
    assert!(m0.iter().all(|&m| m > 0.01), "{name}: the room at the origin is dark: {m0:?}");
    let placements = [
        ("far", 1.0, DVec3::new(1.0e5, 1.0e5, 1.0e5)),
        ("far-mixed", 1.0, DVec3::new(-3.0e5, 2.0e4, 1.25e5)),
        ("small", 1.0e-3, DVec3::ZERO),
        ("large", 1.0e3, DVec3::ZERO),
    ];
    for (what, scale, offset) in placements {
        let rgb = render_room(dir.path(), &format!("{name}-{what}"), scale, offset, how);
        let m = mean(&rgb);
        let e = rel_mse(&origin, &rgb);
        eprintln!("{name} {what}: means {m:?} against {m0:?}, relMSE {e:.5}");
        for c in 0..3 {
            let r = m[c] / m0[c];
            assert!(
                (r - 1.0).abs() <= mean_tol,
                "{name} {what}: channel {c} mean {} against {} at the origin",
                m[c],
                m0[c]
            );
        }
        assert!(e <= noise, "{name} {what}: relMSE {e} against the origin's image (noise bound {noise})");
    }
}

#[test]
fn reference_renders_the_same_room_at_any_scale_and_far_from_the_origin() {
    check_placements("reference", Render::Reference { spp: 32 }, 0.03, 0.02);
}

#[test]
fn ray_traced_direct_light_and_gi_render_the_same_room_at_any_scale_and_far_from_the_origin() {
    // The emitters' direct light (ris) with ray-traced shadows and one bounce of ray-traced GI,
    // four frames accumulated: the passes whose ray offsets and shadow-ray ends a placement could
    // break.
    let technique: fn(Options) -> Options = |o| o.ris(4).rt_shadows(0.0, 0.0).rt_gi(1);
    check_placements("rt", Render::Frames { frames: 4, technique }, 0.03, 0.02);
}
