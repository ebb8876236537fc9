//! The environment in the frame and in the reference path tracer, against this file's own
//! arithmetic (the mapping u = atan2(x, −z) / 2π, v = acos(y) / π written out again, brute-force
//! sums over the map):
//! - the background shows the map in the direction each pixel looks (the direct pass and the
//!   reference's camera rays);
//! - a constant environment lights a scene as the constant sky of the same radiance does;
//! - a white sphere (albedo 1, convex: every bounce escapes) under an environment shows, at each
//!   facet, the cosine-weighted mean of the map around its normal: in the reference (next-event
//!   estimation through the table with MIS, a patchy map) and in the direct pass (the irradiance
//!   harmonics, a smooth map they hold exactly).

use std::time::Instant;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_compiler::ir::{EnvironmentImage, Material, Scene};
use kiln_format::sections::Vertex;
use kiln_player::camera::CameraOverride;
use kiln_player::reference::{Sampling, render_with};
use kiln_test_support::gpu_test;
use kiln_tests::boxes::{cuboid, quad};
use kiln_tests::{Options, compile};

use crate::harness::{Pinhole, fast_settings, render};

const W: u32 = 32;
const H: u32 = 24;

/// A `width` × `width / 2` environment of `f` at its texel centres.
fn environment(width: u32, f: impl Fn(DVec3) -> [f64; 3]) -> EnvironmentImage {
    kiln_tests::equirect::image(width, |d| f(DVec3::from_array(d)))
}

/// The cosine-weighted mean of `f` around unit n (irradiance / π), summed over a fine grid.
fn irradiance_over_pi(n: DVec3, f: &impl Fn(DVec3) -> [f64; 3]) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for (_, _, d, dw) in kiln_tests::equirect::texels(512, 256) {
        let d = DVec3::from_array(d);
        let c = n.dot(d).max(0.0) * dw / std::f64::consts::PI;
        for (s, v) in sum.iter_mut().zip(f(d)) {
            *s += v * c;
        }
    }
    sum
}

fn camera(p: &Pinhole) -> CameraOverride {
    let c = p.file_camera();
    CameraOverride {
        position: c.position.map(f64::from),
        target: c.target.map(f64::from),
        vfov_degrees: Some(c.vfov_degrees as f64),
    }
}

fn reference(file: &std::path::Path, cam: &Pinhole, spp: u32, seed: u32) -> Vec<f32> {
    let sampling = Sampling { spp, seed, bounces: 0, progress: false };
    let o = Options::new(file, W, H).reference().camera(camera(cam)).build();
    render_with(&o, sampling, Instant::now()).expect("reference render").1
}

#[test]
fn the_background_shows_the_environment_where_it_lies() {
    let dir = gpu_test!();
    // Each channel a different function of the direction: a flipped latitude or a mirrored or
    // shifted longitude changes every pixel by far more than the tolerance.
    let f = |d: DVec3| [1.0 + d.y, 1.0 + d.x, 1.0 - d.z];
    // Geometry only behind the camera.
    let mut s = kiln_tests::scene_of(&[[
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::new(1.0, 0.0, 5.0),
        Vec3::new(0.0, 1.0, 5.0),
    ]]);
    s.environment = Some(environment(256, f));
    let bytes = compile(s, fast_settings());
    let cam = Pinhole::new([0.0, 0.0, 0.0], [0.4, 0.3, -1.0], [0.0, 1.0, 0.0], 80.0, W, H);
    let (frame, _) =
        render(dir.path(), "background", &bytes, |file| Options::new(file, W, H).camera(camera(&cam)));
    let file = dir.path().join("background.kiln");
    let traced = reference(&file, &cam, 16, 1);
    for (name, rgb, tolerance) in [("direct pass", &frame, 0.02), ("reference", &traced, 0.04)] {
        let mut worst: f64 = 0.0;
        for y in 0..H {
            for x in 0..W {
                let want = f(cam.ray(x, y, W, H));
                let i = ((y * W + x) * 3) as usize;
                for c in 0..3 {
                    let err = (rgb[i + c] as f64 - want[c]).abs() / 2.0;
                    worst = worst.max(err);
                    assert!(
                        err < tolerance,
                        "{name}: pixel ({x}, {y}) channel {c}: {} vs {}",
                        rgb[i + c],
                        want[c]
                    );
                }
            }
        }
        eprintln!("{name}: worst background error {worst:.4} of the range");
    }
}

/// A floor, a grey block and a rough metal block.
fn blocks() -> Scene {
    let mut s = Scene { name: "blocks".into(), ..Default::default() };
    s.materials.push(Material { name: "grey".into(), gpu: lambert_material([0.5; 3]) });
    s.materials.push(Material { name: "metal".into(), gpu: crate::harness::metal(0.9, 0.5) });
    quad(
        &mut s,
        [Vec3::new(-2., 0., -2.), Vec3::new(-2., 0., 2.), Vec3::new(2., 0., 2.), Vec3::new(2., 0., -2.)],
        0,
    );
    cuboid(&mut s, Vec3::new(-1.0, 0.0, -0.5), Vec3::new(-0.2, 0.8, 0.3), 0, false);
    cuboid(&mut s, Vec3::new(0.3, 0.0, -0.3), Vec3::new(1.0, 0.5, 0.4), 1, false);
    s
}

#[test]
fn a_constant_environment_lights_as_the_constant_sky() {
    let dir = gpu_test!();
    // 0.75 is exact in E5B9G9R9.
    let mut sky = blocks();
    sky.sky.radiance = [0.75; 3];
    let mut env = blocks();
    env.environment = Some(environment(64, |_| [0.75; 3]));
    let cam = Pinhole::new([0.5, 2.0, 3.5], [0.0, 0.3, 0.0], [0.0, 1.0, 0.0], 50.0, W, H);
    let opts = |file: &std::path::Path| Options::new(file, W, H).camera(camera(&cam));
    let (a, _) = render(dir.path(), "sky", &compile(sky, fast_settings()), opts);
    let (b, _) = render(dir.path(), "env", &compile(env, fast_settings()), opts);
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!((x - y).abs() <= 2e-3 * x.max(0.05), "direct pass, value {i}: sky {x}, environment {y}");
    }
    let mean = |v: &[f32]| v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    let (ra, rb) = (
        mean(&reference(&dir.path().join("sky.kiln"), &cam, 64, 1)),
        mean(&reference(&dir.path().join("env.kiln"), &cam, 64, 2)),
    );
    eprintln!("reference mean: constant sky {ra:.4}, constant environment {rb:.4}");
    assert!((ra - rb).abs() < 0.02 * ra, "reference: sky {ra}, environment {rb}");
}

/// A unit sphere of 8 · 4³ flat facets (a subdivided octahedron), albedo 1.
fn sphere() -> (Scene, Vec<[DVec3; 3]>) {
    let mut tris: Vec<[DVec3; 3]> = Vec::new();
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                let (a, b, c) = (DVec3::new(sx, 0., 0.), DVec3::new(0., sy, 0.), DVec3::new(0., 0., sz));
                // Counter-clockwise seen from outside.
                tris.push(if sx * sy * sz > 0.0 { [a, b, c] } else { [a, c, b] });
            }
        }
    }
    for _ in 0..3 {
        tris = tris
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = ((a + b).normalize(), (b + c).normalize(), (c + a).normalize());
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    let mut s = Scene { name: "sphere".into(), ..Default::default() };
    s.materials.push(Material { name: "white".into(), gpu: lambert_material([1.0; 3]) });
    for t in &tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize().as_vec3();
        let base = s.vertices.len() as u32;
        for p in t {
            s.vertices.push(Vertex { position: p.as_vec3().to_array(), normal: n.to_array() });
        }
        s.triangles.push([base, base + 1, base + 2]);
        s.triangle_materials.push(0);
    }
    (s, tris)
}

/// The facet normal each pixel's centre ray meets first, if any (brute force over the facets).
fn facets(cam: &Pinhole, tris: &[[DVec3; 3]]) -> Vec<Option<DVec3>> {
    (0..W * H)
        .map(|i| {
            let d = cam.ray(i % W, i / W, W, H);
            let mut best: Option<(f64, DVec3)> = None;
            for &[a, b, c] in tris {
                let n = (b - a).cross(c - a);
                let t = (a - cam.eye).dot(n) / d.dot(n);
                let p = cam.eye + d * t;
                let inside =
                    [(a, b), (b, c), (c, a)].iter().all(|&(u, v)| (v - u).cross(p - u).dot(n) >= 0.0);
                if t > 0.0 && inside && best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, n.normalize()));
                }
            }
            best.map(|(_, n)| n)
        })
        .collect()
}

#[test]
fn a_white_sphere_shows_the_environment_around_each_facet() {
    let dir = gpu_test!();
    let cam = Pinhole::new([0.3, 0.8, 3.2], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 42.0, W, H);
    let (scene, tris) = sphere();
    let normals = facets(&cam, &tris);
    // The reference: a patchy map (a bright patch 25° across, a warm horizon, a dark ground),
    // which only next-event estimation through the table and its MIS weights get right quickly.
    let patchy = |d: DVec3| {
        if d.dot(DVec3::new(0.6, 0.5, 0.62).normalize()) > 0.976 {
            [12.0, 11.0, 9.0]
        } else if d.y > 0.0 {
            [0.3 + 0.4 * (1.0 - d.y), 0.35, 0.6]
        } else {
            [0.1, 0.08, 0.05]
        }
    };
    let mut s = scene.clone();
    s.environment = Some(environment(256, patchy));
    std::fs::write(dir.path().join("patchy.kiln"), compile(s, fast_settings())).unwrap();
    let rgb = reference(&dir.path().join("patchy.kiln"), &cam, 256, 3);
    // Pixels whose footprint lies on the sphere (the reference averages over the pixel).
    let interior = |i: usize| {
        let (x, y) = ((i as u32 % W) as i64, (i as u32 / W) as i64);
        (-1..=1).all(|dy| {
            (-1..=1).all(|dx| {
                let (u, v) = (x + dx, y + dy);
                u >= 0
                    && v >= 0
                    && u < W as i64
                    && v < H as i64
                    && normals[(v * W as i64 + u) as usize].is_some()
            })
        })
    };
    let (mut got, mut want, mut count) = ([0.0f64; 3], [0.0f64; 3], 0);
    for (i, n) in normals.iter().enumerate() {
        let Some(n) = n.filter(|_| interior(i)) else { continue };
        let e = irradiance_over_pi(n, &patchy);
        for c in 0..3 {
            got[c] += rgb[3 * i + c] as f64;
            want[c] += e[c];
        }
        count += 1;
    }
    eprintln!("reference over {count} sphere pixels: {got:?} against {want:?}");
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() < 0.03 * want[c],
            "reference channel {c}: {} vs {}",
            got[c],
            want[c]
        );
    }
    // The direct pass: a smooth map (linear in the direction), which band 1 of the harmonics
    // holds exactly: every sphere pixel within 2 %.
    let smooth = |d: DVec3| [0.6 + 0.3 * d.y, 0.5 + 0.25 * d.x, 0.5 - 0.2 * d.z];
    let mut s = scene;
    s.environment = Some(environment(128, smooth));
    let (frame, _) = render(dir.path(), "smooth", &compile(s, fast_settings()), |file| {
        Options::new(file, W, H).camera(camera(&cam))
    });
    for (i, n) in normals.iter().enumerate() {
        let Some(n) = n else { continue };
        let e = irradiance_over_pi(*n, &smooth);
        for c in 0..3 {
            let g = frame[3 * i + c] as f64;
            assert!((g - e[c]).abs() < 0.02 * e[c], "direct pass, pixel {i} channel {c}: {g} vs {}", e[c]);
        }
    }
}
