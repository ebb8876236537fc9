//! The ray-traced passes' running mean carried along a moving camera (`--aa reproject`):
//! against the same camera's converged still image at the last pose, it is far less noisy than
//! restarting at every move, and where a surface was just disoccluded it starts afresh instead
//! of inheriting the occluder's history.

use std::path::Path;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::Sky;
use kiln_player::camera::{CameraOverride, CameraPath};
use kiln_player::render::Aa;
use kiln_player::render::techniques;
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{H, Pinhole, W, fast_settings, render_frames, square, srgb8};

/// Height of the ceiling, of the plate, the plate's half size, the AO radius.
const CEILING: f32 = 1.0;
const PLATE: f32 = 0.5;
const HALF: f32 = 0.2;
const RADIUS: f32 = 2.0;

#[test]
fn reprojected_ao_follows_a_moving_camera_and_restarts_where_disoccluded() {
    let dir = gpu_test!();
    // A floor under a ceiling (as the AO test's) with a plate floating between them; the
    // camera just under the ceiling looks straight down and slides sideways, so that the plate
    // (2.25 times nearer) sweeps over the floor and uncovers a strip of it every frame.
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 20.0).to_vec();
    // The ceiling in strips 0.3 wide with 0.3 gaps across the slide: the floor's AO varies by
    // about a factor of two over 0.6 units (some 27 pixels), so a history read in the wrong
    // place shows.
    for k in -40..40 {
        let (x0, x1) = (k as f32 * 0.6, k as f32 * 0.6 + 0.3);
        let p = |x: f32, z: f32| Vec3::new(x, CEILING, z);
        // Facing down.
        tris.push([p(x0, -20.0), p(x1, 20.0), p(x0, 20.0)]);
        tris.push([p(x0, -20.0), p(x1, -20.0), p(x1, 20.0)]);
    }
    tris.extend(square(PLATE, HALF));
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = lambert_material([srgb8(188); 3]);
    scene.sky = Sky { radiance: [2.0; 3] };
    let eye = |x: f64| [x, 0.9, 0.0];
    let cam = Pinhole::new(eye(0.6), [0.6, 0.0, 0.0], [0.0, 0.0, -1.0], 90.0, W, H);
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let frames = 12u32;
    let pose = |x: f64| format!("{x},0.9,0,{x},0,0,90");
    let path = CameraPath::parse(&format!("{}\n{}\n", pose(-0.6), pose(0.6))).unwrap();
    let last: CameraOverride = pose(0.6).parse().unwrap();
    let ao = move |aa: Aa| move |f: &Path| Options::new(f, W, H).unshadowed().rt_ao(Some(RADIUS)).aa(aa);
    // The converged still image at the last pose.
    let (still, _) = render_frames(dir.path(), "still", &bytes, 64, move |f| {
        ao(Aa::Accumulate(techniques::aa::accumulate::Accumulate))(f).camera(last)
    });
    let moving = |name: &str, aa: Aa| {
        let path = path.clone();
        render_frames(dir.path(), name, &bytes, frames, move |f| ao(aa)(f).camera_path(path.clone())).0
    };
    let carried = moving("reproject", Aa::Reproject(techniques::aa::reproject::Reproject { frames: 32 }));
    let restarted = moving("restart", Aa::Accumulate(techniques::aa::accumulate::Accumulate));

    // Classify the last frame's pixels by geometry computed here: the floor the last 7 frames'
    // eyes saw (it has 6 frames of history at least), the floor the plate hid from the previous
    // frame's eye (disoccluded this frame); pixels within 0.005 of a boundary (in the plate's
    // plane) are left out, and so is the right half of the image, where the floor came into
    // view during the slide.
    let eye_of = |i: u32| DVec3::new(-0.6 + 1.2 * i as f64 / (frames - 1) as f64, 0.9, 0.0);
    let previous_eye = eye_of(frames - 2);
    let under_plate = |p: DVec3, grow: f64| p.x.abs() < HALF as f64 + grow && p.z.abs() < HALF as f64 + grow;
    let hidden_from = |e: DVec3, p: DVec3, grow: f64| {
        let t = (e.y - PLATE as f64) / (e.y - p.y);
        under_plate(e + (p - e) * t, grow)
    };
    let (mut floor, mut fresh) = (Vec::new(), Vec::new());
    for y in 0..H {
        for x in 0..W {
            let d = cam.ray(x, y, W, H);
            let at = |h: f64| cam.eye + d * ((cam.eye.y - h) / -d.y);
            let (top, ground) = (at(PLATE as f64), at(0.0));
            if under_plate(top, 0.005) {
                continue; // the plate, or too near its edge
            }
            let i = (y * W + x) as usize * 3;
            if hidden_from(previous_eye, ground, -0.005) {
                fresh.push(i);
            } else if x < W / 2 && (frames - 7..frames).all(|f| !hidden_from(eye_of(f), ground, 0.005)) {
                floor.push(i);
            }
        }
    }
    let rms = |img: &[f32], px: &[usize]| {
        (px.iter().map(|&i| ((img[i] - still[i]) as f64).powi(2)).sum::<f64>() / px.len() as f64).sqrt()
    };
    let mean = |img: &[f32], px: &[usize]| {
        px.iter().map(|&i| (img[i] - still[i]) as f64).sum::<f64>() / px.len() as f64
    };
    let (rms_carried, rms_restarted) = (rms(&carried, &floor), rms(&restarted, &floor));
    // Disoccluded pixels hold one fresh sample: unbiased, with one sample's spread.
    let (bias, spread) = (mean(&carried, &fresh), rms(&restarted, &fresh));
    eprintln!(
        "moving AO after {frames} frames, against the still image: RMS {rms_carried:.4} carried, \
         {rms_restarted:.4} restarted over {} floor pixels; disoccluded ({} pixels): mean offset {bias:+.4} \
         (one sample's RMS {spread:.4})",
        floor.len(),
        fresh.len()
    );
    assert!(
        floor.len() > 1000 && fresh.len() > 30,
        "{} floor, {} disoccluded pixels",
        floor.len(),
        fresh.len()
    );
    // 6 to 11 frames of history against none, each read bilinearly (which averages neighbours
    // too): measured 4.7× less (0.064 against 0.300); the history read at the pixel's own texel
    // instead of where its point was (lagging the slide across the ceiling's strips) gave 3.1×.
    assert!(
        rms_carried < rms_restarted / 3.8,
        "reprojection did not reduce the noise: {rms_carried} vs {rms_restarted}"
    );
    // Inheriting the plate's history would pull these pixels far off (the plate's top is much
    // more occluded than the floor beside it).
    // Three standard errors of a mean of single samples (measured −0.043 against 0.080; with
    // the plate's history kept, −0.123).
    let bound = 3.0 * spread / (fresh.len() as f64).sqrt();
    assert!(bias.abs() < bound, "disoccluded floor is off by {bias} on average (bound {bound})");
}
