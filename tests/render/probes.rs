//! `--gi probes` (the compiler's irradiance probes) in a raster frame: two closed rooms side by
//! side, the left lit only by an emissive panel under its ceiling, the right by nothing, the wall
//! between them one probe spacing thick. With `--direct none` the probes bring everything: the
//! panel's direct light (their emitted layer) and every bounce.
//! - The lit room's floor matches the reference path tracer's (an independent estimator: the
//!   `--reference` kernel, all bounces) within 15 % on average: the probes are interpolated
//!   between grid points a spacing apart, where the panel's light varies.
//! - The dark room's floor, which the reference shows black, stays below 5 % of the lit one's:
//!   the probes just across the wall see the lit room, and only the Chebyshev test of their
//!   distance maps keeps their light out.
//!
//! And a white furnace for the glossy part: a white metal floor inside a closed box whose black
//! walls glow with radiance Le sees Le in every direction, so (with the split sum's
//! multiple-scattering compensation) it reflects exactly Le — a closed form. The sky outside is
//! black, so a split sum that read the sky instead of the probes along the mirror direction
//! shows a black floor.

use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use kiln_compiler::import::demo::lambert_material;
use kiln_compiler::ir::{Material, Scene};
use kiln_compiler::settings::{ProbeSpacing, Settings};
use kiln_player::camera::CameraOverride;
use kiln_player::reference::{Sampling, render_with};
use kiln_player::render::techniques::gi::{Gi, probes::Probes};
use kiln_test_support::gpu_test;
use kiln_tests::boxes::{cuboid, quad};
use kiln_tests::{Options, compile};

use crate::harness::{fast_settings, render, render_frames, srgb8};

const W: u32 = 32;
const H: u32 = 24;

/// The two rooms (2 × 2 × 2 units, the wall at 0.05 < x < 0.25) and their file's bytes, probes
/// 0.2 apart: the column of probes at x = 0.1 lies in the wall, nearer its lit face, and moves
/// out into the lit room, where it stands beside the dark room's floor across the wall.
fn rooms() -> Vec<u8> {
    let mut s = Scene { name: "rooms".into(), ..Default::default() };
    s.materials.push(Material { name: "grey".into(), gpu: lambert_material([srgb8(188); 3]) });
    let mut glow = lambert_material([0.0; 3]);
    glow.emission = [8.0; 3];
    s.materials.push(Material { name: "panel".into(), gpu: glow });
    cuboid(&mut s, Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 1.0), 0, true);
    cuboid(&mut s, Vec3::new(0.05, 0.0, -1.0), Vec3::new(0.25, 2.0, 1.0), 0, false);
    // The panel under the left room's ceiling, facing down.
    let (y, x0, x1, z) = (1.95, -0.8, -0.3, 0.25);
    quad(&mut s, [Vec3::new(x0, y, -z), Vec3::new(x1, y, -z), Vec3::new(x1, y, z), Vec3::new(x0, y, z)], 1);
    let settings = Settings {
        probes: kiln_compiler::settings::Probes::Auto,
        probe_spacing: Some(ProbeSpacing(0.2)),
        probe_rays: Some(256),
        ..fast_settings()
    };
    compile(s, settings)
}

/// A camera above a room's floor looking straight down, seeing `r` units around x (floor only).
fn above(x: f64, r: f64) -> CameraOverride {
    CameraOverride {
        position: [x, 1.0, 0.0],
        target: [x, 0.0, 0.001],
        vfov_degrees: Some(2.0 * r.atan().to_degrees()),
    }
}

/// Mean of the red channel (the scene is grey).
fn mean(rgb: &[f32]) -> f64 {
    rgb.chunks_exact(3).map(|p| p[0] as f64).sum::<f64>() / (rgb.len() / 3) as f64
}

fn probes(file: &Path, camera: CameraOverride) -> Options {
    Options::new(file, W, H).gi(Gi::Probes(Probes { normal_bias: 0.1, view_bias: 0.2 })).camera(camera)
}

#[test]
fn probes_light_a_room_as_the_reference_does_and_nothing_through_its_wall() {
    let dir = gpu_test!();
    let bytes = rooms();
    let (lit, _) = render(dir.path(), "lit", &bytes, |f| probes(f, above(-0.5, 0.2)));
    let (dark, _) = render(dir.path(), "dark", &bytes, |f| probes(f, above(0.45, 0.2)));
    // The strip of the dark floor beside the wall (0.25 < x < 0.31), whose cell's other corner
    // is the probe that moved out into the lit room.
    let (strip, _) = render(dir.path(), "strip", &bytes, |f| probes(f, above(0.28, 0.03)));
    let file = dir.path().join("lit.kiln");
    let reference = [1u32, 2].map(|seed| {
        let sampling = Sampling { spp: 48, seed, bounces: 16, progress: false };
        let o = Options::new(&file, W, H).reference().camera(above(-0.5, 0.2)).build();
        mean(&render_with(&o, sampling, Instant::now()).expect("reference render").1)
    });
    let (lit, dark, strip, want) =
        (mean(&lit), mean(&dark), mean(&strip), 0.5 * (reference[0] + reference[1]));
    eprintln!(
        "lit floor {lit:.4}, dark floor {dark:.4}, beside the wall {strip:.4}, reference {want:.4} ({:.4}, {:.4})",
        reference[0], reference[1]
    );
    assert!((reference[0] - reference[1]).abs() < 0.03 * want, "the reference is too noisy: {reference:?}");
    assert!((lit - want).abs() <= 0.15 * want, "the lit floor {lit} against the reference {want}");
    // The bound is 5 %; the probes keep it under 1 % even beside the wall (without the
    // Chebyshev test the strip measured 5.5 %).
    for (name, floor) in [("dark floor", dark), ("floor beside the wall", strip)] {
        assert!(floor <= 0.01 * lit, "light leaks through the wall: the {name} {floor} against {lit}");
    }
}

/// The furnace: a closed 2-unit box of walls of albedo `rho` emitting `LE`, a white metal floor of
/// `roughness`. White metal reflects all it receives, so the radiance is the same everywhere and
/// in every direction: LE / (1 − rho).
fn furnace(rho: f32, roughness: f32) -> Vec<u8> {
    let mut s = Scene { name: "furnace".into(), ..Default::default() };
    let mut wall = lambert_material([rho; 3]);
    wall.emission = [LE; 3];
    s.materials.push(Material { name: "glow".into(), gpu: wall });
    let metal = kiln_format::sections::GpuMaterial {
        base_color: [1.0; 4],
        metallic: 1.0,
        roughness,
        ..Default::default()
    };
    s.materials.push(Material { name: "metal".into(), gpu: metal });
    cuboid(&mut s, Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 1.0), 0, true);
    let y = 0.01;
    quad(
        &mut s,
        [Vec3::new(-0.9, y, 0.9), Vec3::new(0.9, y, 0.9), Vec3::new(0.9, y, -0.9), Vec3::new(-0.9, y, -0.9)],
        1,
    );
    let settings = Settings {
        probes: kiln_compiler::settings::Probes::Auto,
        probe_spacing: Some(ProbeSpacing(0.5)),
        probe_rays: Some(256),
        ..fast_settings()
    };
    compile(s, settings)
}

const LE: f32 = 0.75;

/// Looking down at the floor's middle from a little aside, so that the mirror direction is not
/// the wall straight above only.
fn at_the_floor() -> CameraOverride {
    CameraOverride { position: [0.3, 1.0, 0.2], target: [0.0, 0.0, 0.0], vfov_degrees: Some(20.0) }
}

#[test]
fn probes_light_glossy_metal_by_what_it_mirrors() {
    let dir = gpu_test!();
    let bytes = furnace(0.0, 0.5);
    let (floor, _) = render(dir.path(), "furnace", &bytes, |f| probes(f, at_the_floor()));
    let floor = mean(&floor);
    eprintln!("metal floor {floor:.4} against Le {LE}");
    assert!((floor - f64::from(LE)).abs() <= 0.03 * f64::from(LE), "the metal floor {floor} against Le {LE}");
}

/// The ray-traced reflections' hits lit by the probes: in the furnace with walls of albedo 1/2,
/// the metal floor reflects walls of radiance LE / (1 − 1/2) = 2 LE, of which LE is their
/// emission and LE the light they reflect, which only the probes give at the hits (the sky is
/// black, and the reflections' own light terms are the analytic lights: none here). Planted and
/// seen failing: the hits lit by the sky as before (the floor 0.7496 against 1.5).
#[test]
fn ray_traced_reflections_see_the_probes_light_at_their_hits() {
    let dir = gpu_test!();
    let rho = 0.5;
    let bytes = furnace(rho, 0.2);
    let frames = 8;
    let (floor, _) = render_frames(dir.path(), "furnace-rt", &bytes, frames, |f| {
        probes(f, at_the_floor()).rt_reflections(kiln_tests::Reflections::Full)
    });
    let (got, want) = (mean(&floor), f64::from(LE / (1.0 - rho)));
    eprintln!("metal floor through ray-traced reflections {got:.4}, closed form {want:.4}");
    assert!((got - want).abs() <= 0.05 * want, "the metal floor {got} against LE / (1 - rho) = {want}");
}

/// A table under an open sky: a 2 × 2 top at y = 1 facing up over a 4 × 4 floor, under a uniform
/// sky of radiance `SKY`, nothing else. The top is the highest thing in the scene, so every probe
/// lies below it (the volume's outermost layer is 0.1 under it, the probes between top and floor
/// see its dark underside); its upward face sees the whole sky, which sends it the irradiance
/// π·SKY: a diffuse top of albedo ρ shows ρ·SKY. Before the probes stepped aside past their
/// volume's last layer on a side the surface faces out of, the top read the probes under it
/// (Khronos ToyCar's roof: a dark patch over its decal). Planted and seen failing: the probes
/// kept at full weight there (the top black: 0.0000 against 0.4023).
#[test]
fn a_surface_facing_out_of_the_probe_volume_sees_the_sky() {
    const SKY: f32 = 0.8;
    let dir = gpu_test!();
    let rho = srgb8(188);
    let mut s = Scene { name: "table".into(), ..Default::default() };
    s.materials.push(Material { name: "grey".into(), gpu: lambert_material([rho; 3]) });
    let (r, y) = (2.0, 1.0);
    quad(
        &mut s,
        [Vec3::new(-r, 0.0, r), Vec3::new(r, 0.0, r), Vec3::new(r, 0.0, -r), Vec3::new(-r, 0.0, -r)],
        0,
    );
    let t = 1.0;
    quad(&mut s, [Vec3::new(-t, y, t), Vec3::new(t, y, t), Vec3::new(t, y, -t), Vec3::new(-t, y, -t)], 0);
    s.sky = kiln_format::manifest::Sky { radiance: [SKY; 3] };
    let settings = Settings {
        probes: kiln_compiler::settings::Probes::Auto,
        probe_spacing: Some(ProbeSpacing(0.2)),
        probe_rays: Some(64),
        ..fast_settings()
    };
    let bytes = compile(s, settings);
    // Straight down onto the middle of the top, seeing only the top.
    let camera =
        CameraOverride { position: [0.0, 3.0, 0.0], target: [0.0, 0.0, 0.001], vfov_degrees: Some(10.0) };
    let (top, _) = render(dir.path(), "table", &bytes, |f| probes(f, camera));
    let (got, want) = (mean(&top), (rho * SKY) as f64);
    eprintln!("the table's top {got:.4}, closed form {want:.4}");
    assert!((got - want).abs() <= 0.02 * want, "the table's top {got} against rho * sky {want}");
}
