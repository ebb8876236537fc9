//! Path-traced diffuse GI (`--gi rt`) against the reference path tracer: with N bounces, the
//! direct pass plus GI must converge to the reference limited to N + 1 scattering events: under
//! a lit ceiling (point light, emissive panel, sky), and beside a wall that reflects the sky.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_compiler::settings::{Settings, VoxelRes};
use kiln_format::linespace::Variants;
use kiln_format::manifest::{LightKind, Sky};
use kiln_player::reference::{Sampling, render_with};
use kiln_player::render::Readable;
use kiln_player::render::techniques::gi::linespace::GiStructure;
use kiln_player::session::Session;
use kiln_test_support::{gpu_test, require, vulkan};
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{Pinhole, fast_settings, light, square, srgb8};

/// The image: tiny, lavapipe traces it on the CPU.
const W: u32 = 32;
const H: u32 = 24;

/// Frames per GI estimate, samples per pixel per reference estimate (each taken twice).
const FRAMES: u32 = 96;
const SPP: u32 = 96;

/// Renders `frames` frames twice with independent random numbers (the per-frame seed runs on;
/// a camera nudged for one frame in between restarts the average) and returns both averages'
/// RGB radiance.
fn two_estimates(o: &Options, frames: u32) -> [Vec<f32>; 2] {
    let mut o = o.clone().build();
    o.readback = Some(Readable::Radiance);
    let mut session = Session::open(&o, Instant::now()).expect("session");
    let read = |session: &mut Session| {
        for f in 0..frames {
            session.frame(f + 1 == frames).expect("frame");
        }
        assert_eq!(session.renderer.accumulated(), frames);
        let bytes = session.readback.as_mut().and_then(|r| r.buffer.mapped()).expect("host-visible readback");
        let rgba: Vec<f32> = bytes[..(W * H * 16) as usize]
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect::<Vec<f32>>()
    };
    let first = read(&mut session);
    let still = session.camera;
    session.camera.position += DVec3::new(1e-3, 0.0, 0.0);
    session.frame(false).expect("frame");
    session.camera = still;
    let second = read(&mut session);
    assert_eq!(session.close(), 0, "validation errors");
    [first, second]
}

/// Mean of the first channel over the pixels of `rect` (x0, y0, x1, y1; the scene is grey).
fn region_mean(rgb: &[f32], rect: (u32, u32, u32, u32)) -> f64 {
    let (x0, y0, x1, y1) = rect;
    let mut sum = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            sum += rgb[((y * W + x) * 3) as usize] as f64;
        }
    }
    sum / ((x1 - x0) * (y1 - y0)) as f64
}

/// The mean of two independent estimates over `rect` and the standard deviation of that mean,
/// measured from their difference: per pixel, (a − b)² / 2 estimates one estimate's variance.
fn mean_and_noise(two: &[Vec<f32>; 2], rect: (u32, u32, u32, u32)) -> (f64, f64) {
    let [a, b] = two;
    let mean = 0.5 * (region_mean(a, rect) + region_mean(b, rect));
    let (x0, y0, x1, y1) = rect;
    let n = ((x1 - x0) * (y1 - y0)) as f64;
    let mut var = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            let i = ((y * W + x) * 3) as usize;
            let d = (a[i] - b[i]) as f64;
            var += d * d / 2.0;
        }
    }
    // Variance of one estimate's pixel, then of the mean of 2n independent pixels.
    (mean, (var / n / (2.0 * n)).sqrt())
}

#[test]
fn gi_plus_direct_light_converges_to_the_reference_of_one_more_bounce_under_a_lit_ceiling() {
    let dir = gpu_test!();
    // A diffuse floor under a diffuse ceiling (2 × 2 units at height 1) lit by a point light
    // between them, an emissive panel just below the ceiling and a dim sky around it. The direct
    // pass lights the floor from the point light; GI with one bounce adds the panel (which only
    // GI sees: the direct pass samples no emissive triangles), the sky where the ceiling does not
    // hide it, and the light of the point light and the panel that the ceiling reflects. That is
    // exactly what the reference counts with two scattering events.
    let file = lit_ceiling(dir.path(), fast_settings());
    let none = two_estimates(&Options::new(&file, W, H).unshadowed(), 1);
    // One bounce against two scattering events, and (through the MIS-weighted continuation) two
    // against three.
    for gi_bounces in [1u32, 2] {
        for q in converges(&file, gi_bounces) {
            let (m_none, _) = mean_and_noise(&none, q.rect);
            eprintln!("  no GI {m_none:.4}");
            // Without GI the floor misses the panel and the ceiling's light (the sky's ambient,
            // unoccluded, does not make up for them): the test can tell.
            assert!(
                q.reference - m_none > 4.0 * q.tolerance,
                "quadrant {:?}: without GI {m_none} is not clearly darker than {}",
                q.rect,
                q.reference
            );
        }
    }
}

/// A diffuse floor under a diffuse ceiling (2 × 2 units at height 1) lit by a point light
/// between them, an emissive panel just below the ceiling and a dim sky around it, compiled with
/// `settings` into `dir`.
fn lit_ceiling(dir: &Path, settings: Settings) -> PathBuf {
    let albedo = srgb8(188); // stored exactly by the sRGB G-buffer
    let cam = Pinhole::new([0.0, 0.9, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 90.0, W, H);
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 20.0).to_vec();
    let ceiling = square(1.0, 1.0).map(|t| [t[0], t[2], t[1]]); // facing down
    let panel = square(0.0, 0.25).map(|t| [t[0], t[2], t[1]].map(|p| p + Vec3::new(-0.3, 0.95, 0.1)));
    tris.extend(ceiling);
    tris.extend(panel);
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = lambert_material([albedo; 3]);
    let mut glow = lambert_material([0.0; 3]);
    glow.emission = [4.0; 3];
    scene.materials.push(kiln_compiler::ir::Material { name: "panel".into(), gpu: glow });
    let n = scene.triangle_materials.len();
    scene.triangle_materials[n - 2..].fill(1);
    scene.lights.push(light(LightKind::Point, [0.3, 0.5, 0.2], [0.0, -1.0, 0.0], 1.0));
    scene.sky = Sky { radiance: [0.1; 3] };
    scene.cameras.push(cam.file_camera());
    let file = dir.join("lit-ceiling.kiln");
    std::fs::write(&file, compile(scene, settings)).unwrap();
    file
}

#[test]
fn gi_through_the_line_space_converges_to_the_reference_with_candidates_and_near_it_with_pnmt() {
    require!(vulkan());
    // The same estimator as --gi rt: with the candidate lists every bounce hit is exact, and the
    // shadow rays through the binary line space are exact within two cells of their ends, which
    // covers every feeler under the 1-unit ceiling at both resolutions below. So the result
    // converges to the reference as --gi rt does. PNMT's hits are the shafts' stored midpoint
    // hits, one per shaft and direction: biased. At 32 cells over the 20-unit floor (cells 0.625
    // units, below the ceiling's height) the bias stays within 10 % of the floor's radiance
    // (measured: see the printed quadrants); at 8 cells a floor cell also holds the ceiling, the
    // floor is its first surface from below, and the panel and ceiling are lost (-30 %).
    let dir = tempfile::tempdir().unwrap();
    let settings = |res| Settings {
        shaft_variants: Some(Variants::ALL),
        voxel_res: VoxelRes::Cells(res),
        shaft_res: Some(4),
        ..fast_settings()
    };
    let file = lit_ceiling(dir.path(), settings(8));
    let candidates = Options::new(&file, W, H).unshadowed().line_space_gi(1, GiStructure::Candidates);
    converges_with(&file, 1, &candidates, 0.0);
    let fine = tempfile::tempdir().unwrap();
    let file = lit_ceiling(fine.path(), settings(32));
    let pnmt = Options::new(&file, W, H).unshadowed().line_space_gi(1, GiStructure::Pnmt);
    converges_with(&file, 1, &pnmt, 0.30);
}

#[test]
fn gi_brings_the_sky_that_a_wall_reflects_onto_the_floor() {
    let dir = gpu_test!();
    // A floor beside a tall bright wall under a sky, no light: the floor sees the sky directly
    // and through the wall, which sees it over half its hemisphere. The sky is no emitter of the
    // next-event table, so at GI's last hit only an escaping ray brings it; without that the
    // wall's share (about a sixth of the floor's radiance here) is missing.
    let cam = Pinhole::new([-0.8, 1.2, 0.0], [0.2, 0.0, 0.0], [0.0, 1.0, 0.0], 70.0, W, H);
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 20.0).to_vec();
    // The wall x = 0.5, 4 high, facing −x.
    let p = |y: f32, z: f32| Vec3::new(0.5, y, z);
    tris.push([p(0.0, -20.0), p(4.0, 20.0), p(4.0, -20.0)]);
    tris.push([p(0.0, -20.0), p(0.0, 20.0), p(4.0, 20.0)]);
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = lambert_material([srgb8(188); 3]);
    scene
        .materials
        .push(kiln_compiler::ir::Material { name: "wall".into(), gpu: lambert_material([srgb8(230); 3]) });
    let n = scene.triangle_materials.len();
    scene.triangle_materials[n - 2..].fill(1);
    scene.sky = Sky { radiance: [1.0; 3] };
    scene.cameras.push(cam.file_camera());
    let file = dir.path().join("wall.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    converges(&file, 1);
}

/// A quadrant's comparison.
struct Quadrant {
    rect: (u32, u32, u32, u32),
    reference: f64,
    tolerance: f64,
}

/// Asserts that direct light plus `--gi rt` with `gi_bounces` converges to the reference of
/// `gi_bounces` + 1 scattering events in each quadrant of the image of `file` (unshadowed: the
/// direct pass's lights must see every pixel); returns the comparisons.
fn converges(file: &Path, gi_bounces: u32) -> Vec<Quadrant> {
    converges_with(file, gi_bounces, &Options::new(file, W, H).unshadowed().rt_gi(gi_bounces), 0.0)
}

/// [`converges`] for the GI technique of `options`, allowing a bias of `bias` (relative) on top
/// of the noise.
fn converges_with(file: &Path, gi_bounces: u32, options: &Options, bias: f64) -> Vec<Quadrant> {
    let t = Instant::now();
    let gi = two_estimates(options, FRAMES);
    let reference: [Vec<f32>; 2] = [1u32, 2].map(|seed| {
        let sampling = Sampling { spp: SPP, seed, bounces: gi_bounces + 1, progress: false };
        let o = Options::new(file, W, H).reference().build();
        render_with(&o, sampling, Instant::now()).expect("reference render").1
    });
    eprintln!("gi-bounces {gi_bounces}: rendered in {:.1} s", t.elapsed().as_secs_f64());
    let (hw, hh) = (W / 2, H / 2);
    let mut out = Vec::new();
    for rect in [(0, 0, hw, hh), (hw, 0, W, hh), (0, hh, hw, H), (hw, hh, W, H)] {
        let (m_gi, s_gi) = mean_and_noise(&gi, rect);
        let (m_ref, s_ref) = mean_and_noise(&reference, rect);
        // Four standard deviations of the difference, plus 0.5 % for the sRGB G-buffer's
        // approximate decoding on lavapipe and the direct pass's pixel centres against the
        // reference's pixel-wide box filter.
        let tolerance = 4.0 * (s_gi * s_gi + s_ref * s_ref).sqrt() + (0.005 + bias) * m_ref;
        eprintln!(
            "quadrant {rect:?}: GI {m_gi:.4} (±{s_gi:.4}), reference {m_ref:.4} (±{s_ref:.4}); \
             tolerance {tolerance:.4}"
        );
        assert!(
            (m_gi - m_ref).abs() <= tolerance,
            "gi-bounces {gi_bounces}, quadrant {rect:?}: GI + direct {m_gi} vs the reference of {} \
             scattering events {m_ref} (tolerance {tolerance})",
            gi_bounces + 1
        );
        out.push(Quadrant { rect, reference: m_ref, tolerance });
    }
    out
}
