//! Screen-space GI (`--gi ssgi`) against the irradiance a red wall gives the white floor in
//! front of it, integrated here over the wall, and its documented limitation: with the wall off
//! screen, the floor gets no red at all.
//!
//! The wall glows red and reflects nothing (black albedo, emission L): its radiance is L exactly,
//! with no light bounced back from the floor, so the closed form is the whole answer (a sunlit
//! wall would also reflect the lit floor's light, ~25 % more, which a closed form here would
//! have to integrate twice). The sky is black; a sun lights the floor, whose light reaches no
//! other surface it could come back from (the floor is flat, the wall black), so the floor's
//! radiance with SSGI minus without is ρ_floor · E_wall / π. The gathered light reaches the
//! floor through the lit pyramid (the previous frame's radiance), as any lit surface's would.

use std::f64::consts::PI;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::{LightKind, Sky};
use kiln_player::render::techniques;
use kiln_player::render::{Gi, ScreenFraction};
use kiln_test_support::{require, vulkan};
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{H, Pinhole, W, fast_settings, light, pixel_xy, render_frames, square, srgb8};

/// The wall: the plane z = 0 facing +z, x in [−WALL_HALF, WALL_HALF], y in [0, WALL_HEIGHT].
const WALL_HALF: f64 = 3.0;
const WALL_HEIGHT: f64 = 3.0;
/// The wall's emitted radiance (red, a little green to tell the channels apart).
const GLOW: [f64; 3] = [1.0, 0.05, 0.0];
/// Frames rendered: the gathered light is the previous frame's, and the running mean (capped at
/// 16 frames) then forgets the first, unlit frames to within (15/16)^24 / 16 ≈ 1 %.
const FRAMES: u32 = 40;

fn floor_albedo() -> f64 {
    srgb8(188) as f64
}

/// The camera that sees the wall and the floor before it.
fn facing() -> Pinhole {
    Pinhole::new([0.0, 2.6, 6.5], [0.0, 0.6, 1.0], [0.0, 1.0, 0.0], 60.0, W, H)
}

/// The camera looking straight down at the floor 1 to 4 units before the wall, which it does
/// not see.
fn away() -> Pinhole {
    Pinhole::new([0.0, 4.0, 2.5], [0.0, 0.0, 2.5], [0.0, 0.0, -1.0], 40.0, W, H)
}

fn scene(cam: &Pinhole) -> Vec<u8> {
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 8.0).to_vec();
    let (s, h) = (WALL_HALF as f32, WALL_HEIGHT as f32);
    let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
    let wall = [[p(-s, 0.0), p(s, 0.0), p(s, h)], [p(-s, 0.0), p(s, h), p(-s, h)]];
    tris.extend(wall);
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = lambert_material([floor_albedo() as f32; 3]);
    let mut glow = lambert_material([0.0; 3]);
    glow.emission = GLOW.map(|c| c as f32);
    scene.materials.push(kiln_compiler::ir::Material { name: "wall".into(), gpu: glow });
    let n = scene.triangle_materials.len();
    scene.triangle_materials[n - 2..].fill(1);
    let sun = Vec3::new(0.0, -1.0, -1.0).normalize();
    scene.lights.push(light(LightKind::Directional, [0.0; 3], sun.to_array(), 2.0));
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.cameras.push(cam.file_camera());
    compile(scene, fast_settings())
}

/// Irradiance at floor point p from the wall of uniform radiance 1 (midpoint rule, 240 × 120
/// cells): ∫ cos θ_p cos θ_w / (d² + ε) dA, with the seed's singularity term ε = 0.1 (eq. 2.12,
/// part of what SSGI estimates; 0 gives the true irradiance, 10 % more at 0.5 units from the
/// wall, 2 % at 1.5).
fn wall_irradiance(p: DVec3, epsilon: f64) -> f64 {
    let (nx, ny) = (240, 120);
    let (dx, dy) = (2.0 * WALL_HALF / nx as f64, WALL_HEIGHT / ny as f64);
    let mut sum = 0.0;
    for j in 0..ny {
        for i in 0..nx {
            let w = DVec3::new(-WALL_HALF + (i as f64 + 0.5) * dx, (j as f64 + 0.5) * dy, 0.0);
            let d = w - p;
            let d2 = d.length_squared();
            // cos θ_p = d.y / |d| (floor normal +y); cos θ_w = p.z / |d| (wall normal +z).
            sum += d.y * p.z / (d2 * (d2 + epsilon)) * dx * dy;
        }
    }
    sum
}

/// The floor point pixel (x, y) of `cam` shows, if any (z > 0: before the wall).
fn floor_point(cam: &Pinhole, x: u32, y: u32) -> Option<DVec3> {
    let d = cam.ray(x, y, W, H);
    if d.y >= 0.0 {
        return None;
    }
    let p = cam.eye + d * (-cam.eye.y / d.y);
    (p.z > 0.0 && p.x.abs() < 8.0 && p.z < 8.0).then_some(p)
}

fn ssgi(tiled: bool) -> Gi {
    Gi::Ssgi(techniques::gi::ssgi::Ssgi {
        samples: 128,
        resolution: ScreenFraction::Half,
        radius: 40,
        voting: true,
        falloff: false,
        frames: 16,
        tiled,
    })
}

/// Per-channel radiance with SSGI (spirals turned per texel or per tile) minus without, for
/// `cam`'s scene.
fn gathered(name: &str, cam: &Pinhole, tiled: bool) -> Vec<f64> {
    let dir = tempfile::tempdir().unwrap();
    let bytes = scene(cam);
    let opts = |gi: Gi| move |f: &std::path::Path| Options::new(f, W, H).unshadowed().gi(gi);
    let (with, _) = render_frames(dir.path(), name, &bytes, FRAMES, opts(ssgi(tiled)));
    let (without, _) = render_frames(
        dir.path(),
        &format!("{name}-off"),
        &bytes,
        1,
        opts(Gi::Off(techniques::gi::none::Off)),
    );
    with.iter().zip(&without).map(|(&a, &b)| a as f64 - b as f64).collect()
}

#[test]
fn ssgi_bleeds_a_red_wall_onto_the_floor_as_the_closed_form_says() {
    require!(vulkan());
    let cam = facing();
    for tiled in [false, true] {
        bleed(&cam, tiled);
    }
}

fn bleed(cam: &Pinhole, tiled: bool) {
    let gain = gathered("ssgi-facing", cam, tiled);
    eprintln!("tiled rotation: {tiled}");
    // Two bands of floor before the wall: near (0.3 to 1 unit) and far (1.5 to 3): their
    // ratio checks the fall-off with distance, each its level.
    let mut bands = [(0.0, 0.0, 0.0, 0usize); 2]; // (got red, expected red, got green, pixels)
    for i in 0..(W * H) as usize {
        let (x, y) = pixel_xy(3 * i);
        let Some(p) = floor_point(cam, x, y) else { continue };
        if p.x.abs() > 2.0 {
            continue;
        }
        let band = match p.z {
            z if (0.3..1.0).contains(&z) => 0,
            z if (1.5..3.0).contains(&z) => 1,
            _ => continue,
        };
        let e = wall_irradiance(p, 0.1);
        let b = &mut bands[band];
        b.0 += gain[3 * i];
        b.1 += floor_albedo() / PI * e * GLOW[0];
        b.2 += gain[3 * i + 1];
        b.3 += 1;
    }
    for (name, (got, expected, green, n)) in ["near", "far"].iter().zip(bands) {
        eprintln!(
            "{name}: {n} pixels, red gain {:.4} against {:.4} (ratio {:.3}), green gain {:.4}",
            got / n as f64,
            expected / n as f64,
            got / expected,
            green / n as f64
        );
    }
    for (name, (got, expected, green, n)) in ["near", "far"].iter().zip(bands) {
        let ratio = got / expected;
        assert!(n > 30, "{name}: only {n} floor pixels");
        // Spiral sampling, half resolution, positions from the pyramids: within 15 %.
        assert!((0.85..1.15).contains(&ratio), "{name}: SSGI's red bleed is {ratio} times the closed form");
        // Each channel as the wall's: green is 5 % of red.
        assert!(
            (green / got - GLOW[1] / GLOW[0]).abs() < 0.01,
            "{name}: green gain {green} against red {got}"
        );
    }
}

#[test]
fn ssgi_gives_nothing_from_a_wall_off_screen() {
    require!(vulkan());
    // The documented limitation: the gather sees only what the screen shows. The floor before
    // the wall would receive the wall's red (the closed form below), but the camera looks down
    // at the sunlit floor alone, and coplanar floor points light each other with cos θ = 0.
    let cam = away();
    let gain = gathered("ssgi-away", &cam, true);
    let (mut got, mut expected, mut n) = (0.0, 0.0, 0);
    for i in 0..(W * H) as usize {
        let (x, y) = pixel_xy(3 * i);
        let Some(p) = floor_point(&cam, x, y) else { continue };
        got += gain[3 * i].abs();
        expected += floor_albedo() / PI * wall_irradiance(p, 0.0) * GLOW[0];
        n += 1;
    }
    eprintln!(
        "off screen: {n} pixels, |red gain| {:.5}, true bleed {:.4}",
        got / n as f64,
        expected / n as f64
    );
    assert_eq!(n, (W * H) as usize, "the camera sees only floor");
    assert!(expected / n as f64 > 0.01, "the true bleed is large enough to tell");
    assert!(got < 0.02 * expected, "SSGI gathered {got} from a wall it cannot see (true {expected})");
}
