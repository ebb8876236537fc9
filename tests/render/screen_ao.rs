//! The screen-space AO techniques (`--ao sao`, `--ao gtao`) against what they estimate: a flat
//! floor is unoccluded, and a floor in front of a wall (an inside corner) is occluded as the
//! technique's own estimator integrates (SAO) or as the closed form of the cosine-weighted
//! visibility says (GTAO). The AO is read per pixel as the radiance with AO over the radiance
//! without (the sky is the only light: the direct pass multiplies its ambient by the AO image).

use std::f64::consts::PI;
use std::path::Path;

use glam::{DVec3, Vec3};
use kiln_format::manifest::Sky;
use kiln_player::render::techniques;
use kiln_player::render::{Ao, ScreenFraction};
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{H, Pinhole, W, fast_settings, pixel_xy, render, square};

/// The camera of both scenes: above the floor, looking down at the foot of the wall z = 0.
const EYE: [f64; 3] = [0.0, 1.6, 3.2];
const TARGET: [f64; 3] = [0.0, 0.3, 0.0];
const VFOV: f64 = 60.0;
/// The AO radius in scene units.
const RADIUS: f64 = 1.0;

fn camera() -> Pinhole {
    Pinhole::new(EYE, TARGET, [0.0, 1.0, 0.0], VFOV, W, H)
}

/// A wall in the plane z = 0 facing +z, x in [−s, s], y in [0, s].
fn wall(s: f32) -> [[Vec3; 3]; 2] {
    let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
    [[p(-s, 0.0), p(s, 0.0), p(s, s)], [p(-s, 0.0), p(s, s), p(-s, s)]]
}

/// What the camera sees through pixel centre (x, y): the point and its normal, on the floor
/// (y = 0, z ≥ 0) or, with `with_wall`, the wall (z = 0, y ≥ 0).
fn surface(cam: &Pinhole, x: u32, y: u32, with_wall: bool) -> Option<(DVec3, DVec3)> {
    let d = cam.ray(x, y, W, H);
    if d.y < 0.0 {
        let p = cam.eye + d * (-cam.eye.y / d.y);
        if p.z >= 0.0 || !with_wall {
            return Some((p, DVec3::Y));
        }
    }
    if with_wall && d.z < 0.0 {
        let p = cam.eye + d * (-cam.eye.z / d.z);
        if p.y >= 0.0 {
            return Some((p, DVec3::Z));
        }
    }
    None
}

/// Renders `bytes` with and without `ao`; the AO per pixel (red channel ratio).
fn ao_image(dir: &Path, name: &str, bytes: &[u8], ao: Ao) -> Vec<f64> {
    let (with, _) = render(dir, name, bytes, |f| Options::new(f, W, H).unshadowed().ao(ao));
    let (without, _) = render(dir, &format!("{name}-off"), bytes, |f| Options::new(f, W, H).unshadowed());
    (0..(W * H) as usize).map(|i| with[3 * i] as f64 / without[3 * i].max(1e-12) as f64).collect()
}

fn scene(with_wall: bool) -> Vec<u8> {
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 20.0).to_vec();
    if with_wall {
        tris.extend(wall(20.0));
    }
    let mut scene = scene_of(&tris);
    scene.sky = Sky { radiance: [1.0; 3] };
    scene.cameras.push(camera().file_camera());
    compile(scene, fast_settings())
}

fn gtao(slices: u32, steps: u32) -> Ao {
    Ao::Gtao(techniques::ao::gtao::Gtao {
        radius: techniques::ao::Radius { radius: Some(RADIUS as f32), reach: 0.05 },
        slices,
        steps,
    })
}

fn sao(resolution: ScreenFraction) -> Ao {
    Ao::Sao(techniques::ao::sao::Sao {
        radius: techniques::ao::Radius { radius: Some(RADIUS as f32), reach: 0.05 },
        samples: 16,
        turns: 7.0,
        resolution,
    })
}

/// (mean, largest |got − expected|) over the pixels `pick` keeps, with their count.
fn compare(ao: &[f64], pick: impl Fn(u32, u32) -> Option<f64>) -> (f64, f64, usize) {
    let (mut sum, mut worst, mut n) = (0.0, 0.0f64, 0);
    for (i, &got) in ao.iter().enumerate() {
        let (x, y) = pixel_xy(3 * i);
        if let Some(expected) = pick(x, y) {
            sum += got / expected;
            worst = worst.max((got - expected).abs());
            n += 1;
        }
    }
    (sum / n as f64, worst, n)
}

#[test]
fn screen_space_ao_of_a_flat_floor_is_one() {
    let dir = gpu_test!();
    // Every sample lies in the centre's tangent plane: SAO's v·n = 0 < β, GTAO's horizons are
    // the tangent plane on both sides. SAO is exactly 1 (up to the depth reconstruction);
    // GTAO's mean over its slices of |n_p|·â is 1 only as the slices' integral over φ, which
    // the per-pixel rotations and the blur approximate with 16 rotations × 3 slices.
    let bytes = scene(false);
    let cam = camera();
    let floor = |x: u32, y: u32| surface(&cam, x, y, false).map(|_| 1.0);
    for (name, ao, tolerance) in [
        ("sao-full", sao(ScreenFraction::Full), 1e-3),
        ("sao-half", sao(ScreenFraction::Half), 1e-3),
        ("gtao", gtao(3, 3), 0.03),
    ] {
        let img = ao_image(dir.path(), name, &bytes, ao);
        let (mean, worst, n) = compare(&img, floor);
        eprintln!("{name}: flat floor AO mean {mean:.5}, largest deviation {worst:.5} over {n} pixels");
        assert!(n > 2000);
        assert!(
            (mean - 1.0).abs() < tolerance && worst < 2.0 * tolerance,
            "{name}: mean {mean}, worst {worst}"
        );
    }
}

/// SAO's estimator (seed 000 eq. 2.21 with erratum 6, its constants; lengths in units of
/// radius/1.8 as the player measures them) at floor pixel (x, y) of the corner scene, its
/// for a radius of `radius` scene units, expected value over the per-pixel rotation φ integrated here with `rotations` equally spaced
/// values: the samples' pixels from the spiral (2.20), the points they show and their normals
/// from this file's own ray casts, every sample at the exact surface (MIP level 0).
fn sao_expected(cam: &Pinhole, x: u32, y: u32, radius: f64, rotations: u32) -> f64 {
    let (n_samples, turns, beta, k, eps, r) = (16u32, 7.0, 0.04, 2.0, 0.01, 1.8);
    let unit = r / radius;
    let (c, n) = surface(cam, x, y, true).expect("a floor pixel");
    let forward = (DVec3::from_array(TARGET) - cam.eye).normalize();
    let z = (c - cam.eye).dot(forward);
    // Pixels per scene unit across the image plane at depth z: H / (2 z tan(fov/2)).
    let r_px = radius * H as f64 / (2.0 * z * (VFOV.to_radians() / 2.0).tan());
    let smooth = |l: f64, r: f64, x: f64| {
        let t = ((x - l) / (r - l)).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    };
    let mut mean = 0.0;
    for j in 0..rotations {
        let phi = 2.0 * PI * (j as f64 + 0.5) / rotations as f64;
        let mut sum = 0.0;
        for i in 0..n_samples {
            let alpha = (i as f64 + 0.5) / n_samples as f64;
            let theta = 2.0 * PI * alpha * turns + phi;
            let sx = (x as f64 + 0.5 + r_px * alpha * theta.cos()).floor();
            let sy = (y as f64 + 0.5 + r_px * alpha * theta.sin()).floor();
            if sx < 0.0 || sy < 0.0 || sx >= W as f64 || sy >= H as f64 {
                continue;
            }
            let Some((s, ni)) = surface(cam, sx as u32, sy as u32, true) else { continue };
            let v = (s - c) * unit;
            let vv = v.dot(v);
            let cos = n.dot(ni).abs();
            let sigma = smooth(0.01, 0.2, cos) * 0.6 + 0.4 + smooth(0.8, 1.0, cos) * 2.0;
            sum += (r * r - vv).max(0.0).powi(3) * ((v.dot(n) - beta) / (vv + eps)).max(0.0) * sigma;
        }
        mean += (1.0 - 5.0 / (r.powi(6) * n_samples as f64) * sum).max(0.0).powf(k);
    }
    mean / rotations as f64
}

/// The cosine-weighted visibility of a floor point at distance d from an infinite wall when
/// only occluders within distance R count. Map the hemisphere's cosine-weighted directions
/// ω = (sinθ cosψ, sinθ sinψ, cosθ) (x towards the wall, z up) to the unit disk by
/// (u, w) = (sinθ cosψ, sinθ sinψ): the measure cosθ sinθ dθ dψ / π becomes area / π. The ray
/// meets the wall at t = d / (sinθ cosψ) = d / u, so it is occluded within R exactly when
/// u > a = d/R: a circular segment of the disk, of area acos(a) − a√(1 − a²). Hence
/// V(d) = 1 − (acos a − a√(1 − a²))/π for a < 1, and 1 beyond (R → ∞ gives ½).
fn wall_visibility(d: f64, r: f64) -> f64 {
    let a = (d / r).min(1.0);
    1.0 - (a.acos() - a * (1.0 - a * a).sqrt()) / PI
}

/// The floor pixels of the corner scene whose AO the checks compare: in front of the wall at
/// distance `d_min` to `d_max`, within |x| < 1 (the samples stay on the screen).
fn corner_pixels(cam: &Pinhole, d_min: f64, d_max: f64) -> impl Fn(u32, u32) -> Option<DVec3> + '_ {
    move |x, y| {
        let (p, n) = surface(cam, x, y, true)?;
        (n == DVec3::Y && p.z >= d_min && p.z <= d_max && p.x.abs() < 1.0).then_some(p)
    }
}

/// Renders `ao` on the corner scene `bytes` and checks its AO at the floor pixels 0.15 to 1.2
/// from the wall against `expected` (what `reference` names): the mean ratio within
/// `tolerance` of 1 and every pixel within `worst_allowed`.
#[allow(clippy::too_many_arguments)]
fn check_corner(
    dir: &Path,
    bytes: &[u8],
    name: &str,
    ao: Ao,
    reference: &str,
    expected: impl Fn(u32, u32, DVec3) -> f64,
    tolerance: f64,
    worst_allowed: f64,
) {
    let cam = camera();
    let (pick, pick_near) = (corner_pixels(&cam, 0.15, 1.2), corner_pixels(&cam, 0.15, 0.4));
    let img = ao_image(dir, name, bytes, ao);
    let (mean, worst, n) = compare(&img, |x, y| pick(x, y).map(|p| expected(x, y, p)));
    // The expected AO's own mean within 0.4 of the wall (how much occlusion there is to find).
    let (near, _, _) =
        compare(&vec![1.0; (W * H) as usize], |x, y| pick_near(x, y).map(|p| 1.0 / expected(x, y, p)));
    eprintln!(
        "{name}: mean ratio to {reference} {mean:.4}, largest deviation {worst:.4} over {n} pixels \
         (its mean within 0.4 of the wall: {near:.3})"
    );
    assert!(n > 300);
    assert!(
        (mean - 1.0).abs() < tolerance && worst < worst_allowed,
        "{name}: mean ratio {mean}, worst {worst}"
    );
}

#[test]
fn sao_of_an_inside_corner_matches_its_estimator_integrated_here() {
    let dir = gpu_test!();
    // The player's per-pixel rotations (16, one per pixel of a 4 × 4 block) and its blur
    // approximate the mean over φ that `sao_expected` integrates; the blur also mixes
    // neighbours a few pixels apart in d. Radius 4 projects to 60 to 120 pixels: most samples
    // read pyramid levels 1 to 2 (m = ⌊log₂(r'α/16)⌋), whose nearest depths rebuilt at the
    // sample's pixel lie off the surface by up to a few pixels' worth of depth; the estimator
    // here reads the exact surface.
    let bytes = scene(true);
    let cam = camera();
    for (name, radius, resolution, tolerance, worst_allowed) in [
        ("sao-corner-full", RADIUS, ScreenFraction::Full, 0.02, 0.08),
        ("sao-corner-half", RADIUS, ScreenFraction::Half, 0.04, 0.15),
        ("sao-corner-r4", 4.0, ScreenFraction::Full, 0.02, 0.05),
    ] {
        let ao = Ao::Sao(techniques::ao::sao::Sao {
            radius: techniques::ao::Radius { radius: Some(radius as f32), reach: 0.05 },
            samples: 16,
            turns: 7.0,
            resolution,
        });
        let expected = |x, y, _| sao_expected(&cam, x, y, radius, 64);
        check_corner(
            dir.path(),
            &bytes,
            name,
            ao,
            "the integrated estimator",
            expected,
            tolerance,
            worst_allowed,
        );
    }
}

#[test]
fn gtao_of_an_inside_corner_matches_the_closed_form_visibility() {
    let dir = gpu_test!();
    let bytes = scene(true);
    for (name, slices, steps, tolerance, worst_allowed) in
        [("gtao-corner-8x24", 8, 24, 0.02, 0.05), ("gtao-corner-3x3", 3, 3, 0.05, 0.15)]
    {
        let ao = Ao::Gtao(techniques::ao::gtao::Gtao {
            radius: techniques::ao::Radius { radius: Some(RADIUS as f32), reach: 0.05 },
            slices,
            steps,
        });
        let expected = |_, _, p: DVec3| wall_visibility(p.z, RADIUS);
        check_corner(dir.path(), &bytes, name, ao, "the closed form", expected, tolerance, worst_allowed);
    }
}

#[test]
fn screen_space_ao_does_not_bleed_across_depth_edges() {
    let dir = gpu_test!();
    // A plate at height 0.5 over the floor, its top facing up: every sample beside it lands on
    // the floor below its tangent plane, so its top is unoccluded up to its edges (as the flat
    // floor), while the floor seen under it, just past its near edge on the screen, is strongly
    // occluded and some 40 % farther from the camera. A blur that mixed them would darken the
    // top's edge pixels.
    let (y0, x0, z0, z1) = (0.5f32, 0.7f32, 0.6f32, 1.6f32);
    let p = |x: f32, z: f32| Vec3::new(x, y0, z);
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 20.0).to_vec();
    tris.extend([[p(-x0, z0), p(-x0, z1), p(x0, z1)], [p(-x0, z0), p(x0, z1), p(x0, z0)]]);
    let mut scene = scene_of(&tris);
    scene.sky = Sky { radiance: [1.0; 3] };
    let cam = camera();
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let top = |x: u32, y: u32| {
        let d = cam.ray(x, y, W, H);
        let q = cam.eye + d * ((y0 as f64 - cam.eye.y) / d.y);
        (q.x.abs() < x0 as f64 && q.z > z0 as f64 && q.z < z1 as f64).then_some(1.0)
    };
    for (name, ao, tolerance) in [
        ("sao-plate", sao(ScreenFraction::Full), 1e-3),
        ("sao-plate-half", sao(ScreenFraction::Half), 1e-3),
        ("gtao-plate", gtao(3, 3), 0.03),
    ] {
        let img = ao_image(dir.path(), name, &bytes, ao);
        let (mean, worst, n) = compare(&img, top);
        // The floor under the plate, for the record: it is occluded.
        let (under, _, _) = compare(&img, |x, y| {
            let d = cam.ray(x, y, W, H);
            let q = cam.eye + d * (-cam.eye.y / d.y);
            (top(x, y).is_none() && q.x.abs() < 0.5 && q.z > 1.0 && q.z < 1.4).then_some(1.0)
        });
        eprintln!(
            "{name}: plate top AO mean {mean:.4}, largest deviation {worst:.4} over {n} pixels; floor under it {under:.3}"
        );
        assert!(n > 300);
        assert!(under < 0.8, "{name}: the floor under the plate is not occluded ({under})");
        assert!(
            (mean - 1.0).abs() < tolerance && worst < 2.0 * tolerance,
            "{name}: mean {mean}, worst {worst}"
        );
    }
}
