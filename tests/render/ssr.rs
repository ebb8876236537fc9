//! Screen-space reflections (`--reflections ssr`) on a mirror floor against this file's own ray
//! arithmetic: an emissive panel standing on the screen appears at the pixels whose mirror ray
//! meets it (the floor's F0 = 1 makes the pixel the incoming radiance itself), nowhere else; where
//! the mirror ray meets the part of the panel beyond the screen's edge the pixel is the split-sum
//! render's (`--reflections none`), while `--reflections rt` shows the panel there; and hits near
//! the screen's edge fade towards the split sum.

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::Sky;
use kiln_player::render::Reflections;
use kiln_player::render::techniques;
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{H, Pinhole, W, fast_settings, metal, render, render_frames, square};

/// The camera: above the floor, looking a little down at the panel.
const EYE: [f64; 3] = [0.0, 1.0, 4.0];
const TARGET: [f64; 3] = [0.0, 0.0, 0.0];
const VFOV: f64 = 60.0;
/// The panel: the plane z = −1 facing the camera, x in [X0, X1], y in [Y0, Y1]: clear of the
/// floor, so that its reflection is a band of its own, and past the screen's top edge (y ≈ 2.43
/// there), where the mirror image of what lies beyond the edge is still on the screen.
const PANEL_Z: f64 = -1.0;
const X0: f64 = -0.6;
const X1: f64 = 0.6;
const Y0: f64 = 0.3;
const Y1: f64 = 4.0;
/// The panel's emitted radiance and the sky's.
const EMITTED: f64 = 4.0;
const SKY: f64 = 0.25;
/// The SSR technique under test: a mirror is well within its roughness limit.
const SSR: Reflections =
    Reflections::Ssr(techniques::reflections::ssr::Ssr { steps: 48, max_roughness: 0.6 });

fn camera() -> Pinhole {
    Pinhole::new(EYE, TARGET, [0.0, 1.0, 0.0], VFOV, W, H)
}

fn scene() -> Vec<u8> {
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 20.0).to_vec();
    let p = |x: f64, y: f64| Vec3::new(x as f32, y as f32, PANEL_Z as f32);
    tris.push([p(X0, Y0), p(X1, Y0), p(X1, Y1)]);
    tris.push([p(X0, Y0), p(X1, Y1), p(X0, Y1)]);
    let mut scene = scene_of(&tris);
    // A smooth metal of base colour 1: F = 1 at every angle, and the split sum's weight times its
    // multiple-scattering compensation is exactly 1, so a floor pixel is its incoming radiance.
    scene.materials[0].gpu = metal(1.0, 0.0);
    let mut light = lambert_material([0.0; 3]);
    light.emission = [EMITTED as f32; 3];
    scene.materials.push(kiln_compiler::ir::Material { name: "panel".into(), gpu: light });
    let n = scene.triangle_materials.len();
    scene.triangle_materials[n - 2..].fill(1);
    scene.sky = Sky { radiance: [SKY as f32; 3] };
    scene.cameras.push(camera().file_camera());
    compile(scene, fast_settings())
}

/// What the mirror ray of a floor pixel meets.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Mirror {
    /// The panel, at this point of the image (texture coordinates; outside [0, 1]²: off screen).
    Panel(f64, f64),
    /// The sky.
    Sky,
}

/// The floor point pixel (x, y) shows (in front of the panel) and what its mirror ray meets;
/// `None` for other pixels.
fn mirror_of(cam: &Pinhole, x: i64, y: i64) -> Option<Mirror> {
    if x < 0 || y < 0 || x >= W as i64 || y >= H as i64 {
        return None;
    }
    let d = cam.ray(x as u32, y as u32, W, H);
    if d.y >= -1e-6 {
        return None;
    }
    let p = cam.eye + d * (-cam.eye.y / d.y);
    if p.z <= PANEL_Z + 0.1 || p.x.abs() > 15.0 || p.z > 15.0 {
        return None;
    }
    // The mirror image of the camera ray about the floor's normal, to the panel's plane.
    let m = DVec3::new(d.x, -d.y, d.z);
    let q = p + m * ((PANEL_Z - p.z) / m.z);
    if (X0..=X1).contains(&q.x) && (Y0..=Y1).contains(&q.y) {
        let (u, v) = cam.project_direction(q - cam.eye).expect("the panel is in front of the camera");
        return Some(Mirror::Panel(u, v));
    }
    Some(Mirror::Sky)
}

/// Whether a floor pixel's neighbours within one pixel are floor pixels whose mirror sees the
/// same (the panel or the sky): the checks leave out pixels that straddle the reflected panel's
/// outline.
fn settled(cam: &Pinhole, x: i64, y: i64) -> bool {
    let panel = |x, y| mirror_of(cam, x, y).map(|m| matches!(m, Mirror::Panel(..)));
    let here = panel(x, y);
    here.is_some() && (-1..=1).all(|dy| (-1..=1).all(|dx| panel(x + dx, y + dy) == here))
}

#[test]
fn ssr_of_a_mirror_floor_shows_an_on_screen_emitter_at_the_mirrored_pixels_and_the_split_sum_elsewhere() {
    let dir = gpu_test!();
    let bytes = scene();
    let cam = camera();
    // SSR shows the previous frame's radiance; the first frame, which has none, makes its lit
    // pyramid again from its own light and traces again: both show the panel.
    let (ssr, _) =
        render_frames(dir.path(), "ssr", &bytes, 3, |f| Options::new(f, W, H).unshadowed().reflections(SSR));
    let (first, _) =
        render(dir.path(), "ssr-first", &bytes, |f| Options::new(f, W, H).unshadowed().reflections(SSR));
    let (none, _) = render(dir.path(), "ssr-none", &bytes, |f| Options::new(f, W, H).unshadowed());
    let (rt, _) = render_frames(dir.path(), "ssr-rt", &bytes, 2, |f| {
        Options::new(f, W, H).unshadowed().rt_reflections(kiln_tests::Reflections::Full)
    });
    let (mut on, mut off, mut sky, mut edge) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for y in 0..H as i64 {
        for x in 0..W as i64 {
            let Some(m) = mirror_of(&cam, x, y) else { continue };
            if !settled(&cam, x, y) {
                continue;
            }
            let i = ((y as u32 * W + x as u32) * 3) as usize;
            match m {
                Mirror::Panel(u, v) => {
                    let border = u.min(1.0 - u).min(v).min(1.0 - v);
                    // Hits well inside (the fade spans 5 % of the image), within 2.5 % of the edge
                    // (the floor's rows step the hit by about 2 % of the image there), and beyond
                    // it by more than a pixel.
                    if border > 0.07 {
                        on.push(i);
                    } else if (0.0..0.025).contains(&border) {
                        edge.push(i);
                    } else if border < -0.015 {
                        off.push(i);
                    }
                }
                Mirror::Sky => sky.push(i),
            }
        }
    }
    eprintln!(
        "floor pixels: {} see the panel on screen, {} near the screen's edge, {} beyond it, {} the sky",
        on.len(),
        edge.len(),
        off.len(),
        sky.len()
    );
    assert!(on.len() > 100 && off.len() > 30 && sky.len() > 500 && !edge.is_empty());
    let stats = |img: &[f32], pixels: &[usize], expected: f64| {
        let r: Vec<f64> = pixels.iter().map(|&i| img[i] as f64 / expected).collect();
        let mean = r.iter().sum::<f64>() / r.len() as f64;
        let worst = r.iter().map(|x| (x - 1.0).abs()).fold(0.0, f64::max);
        (mean, worst)
    };
    // The panel seen in the mirror: its radiance (lavapipe's sRGB and 16-bit normals: ~1 %).
    let (m_on, w_on) = stats(&ssr, &on, EMITTED);
    let (m_rt, w_rt) = stats(&rt, &on, EMITTED);
    // Where the mirror ray meets the panel beyond the screen: SSR cannot see it and shows what
    // the split sum shows (the sky), while the ray-traced reflections show the panel.
    let split = |pixels: &[usize], img: &[f32]| {
        pixels.iter().map(|&i| ((img[i] - none[i]) as f64 / none[i] as f64).abs()).fold(0.0, f64::max)
    };
    let (d_off, d_sky) = (split(&off, &ssr), split(&sky, &ssr));
    let (m_off_rt, _) = stats(&rt, &off, EMITTED);
    let (m_none, w_none) = stats(&none, &sky, SKY);
    // Hits within about a pixel of the screen's edge fade towards the split sum.
    let (m_edge, _) = stats(&ssr, &edge, EMITTED);
    eprintln!(
        "ssr: panel mean ratio {m_on:.4} (worst {w_on:.4}); rt there {m_rt:.4} (worst {w_rt:.4}); \
         off-screen panel: largest relative difference to --reflections none {d_off:.2e} (rt shows \
         {m_off_rt:.3} of the panel); sky: {d_sky:.2e} (none / sky {m_none:.4}, worst {w_none:.4}); \
         hits at the edge: {m_edge:.3} of the panel"
    );
    assert!((m_on - 1.0).abs() < 0.01 && w_on < 0.03, "ssr does not show the panel: {m_on}, worst {w_on}");
    let (m_first, w_first) = stats(&first, &on, EMITTED);
    eprintln!("ssr's first frame: panel mean ratio {m_first:.4} (worst {w_first:.4})");
    assert!(
        (m_first - 1.0).abs() < 0.01 && w_first < 0.03,
        "ssr's first frame does not show the panel: {m_first}, worst {w_first}"
    );
    assert!(split(&sky, &first) < 1e-3, "ssr's first frame differs from the split sum on the sky");
    assert!((m_rt - 1.0).abs() < 0.02, "rt: {m_rt}");
    assert!(d_off < 1e-3, "ssr differs from the split sum where the reflection leaves the screen: {d_off}");
    assert!(m_off_rt > 0.9, "rt does not show the off-screen panel: {m_off_rt}");
    assert!(d_sky < 1e-3, "ssr differs from the split sum where the mirror shows the sky: {d_sky}");
    assert!((m_none - 1.0).abs() < 0.01 && w_none < 0.02, "the split sum does not show the sky: {m_none}");
    let halfway = (SKY + 0.5 * (EMITTED - SKY)) / EMITTED;
    assert!(m_edge < halfway, "hits at the screen's edge do not fade: {m_edge} of the panel");
}
