//! Participating media against closed forms: the reference path tracer and `--media march`.
//! (The reference against an independent renderer with multiple scattering: `tests/mitsuba.rs`,
//! the room full of fog.)

use glam::Vec3;
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::{Bounds, LightKind, Medium, OrthographicCamera, Sky};
use kiln_player::reference::{DEFAULT_SEED, Sampling, render_with};
use kiln_tests::{Options, compile, scene_of, vulkan};

use crate::harness::{Pinhole, fast_settings, light, render, square};

const W: u32 = 32;
const H: u32 = 24;

/// The slab's medium and light: chromatic coefficients (optical depths 0.3 to 1.35 across the
/// slab), forward scattering seen from behind the light's travel.
struct Haze {
    sigma_a: [f32; 3],
    sigma_s: [f32; 3],
    g: f32,
    depth: f32,
    irradiance: f32,
}

const HAZE: Haze =
    Haze { sigma_a: [0.1, 0.2, 0.05], sigma_s: [0.1, 0.4, 0.85], g: 0.5, depth: 1.5, irradiance: 4.0 };

/// The light's direction of travel (cos θ = −0.6 towards a camera looking straight down).
const TRAVEL: [f32; 3] = [0.8, -0.6, 0.0];

/// Henyey–Greenstein, written out here: (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}).
fn henyey_greenstein(g: f64, cos_theta: f64) -> f64 {
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * cos_theta).powf(1.5))
}

/// Straight down through a slab of medium (|x|, |z| < 50, 0 < y < `depth`) onto a black floor,
/// through an orthographic camera 1 unit wide: every pixel's ray crosses the slab far from its
/// sides. The file's bytes.
fn slab_file(
    sigma_a: [f32; 3],
    sigma_s: [f32; 3],
    g: f32,
    depth: f32,
    travel: Vec3,
    irradiance: f32,
) -> Vec<u8> {
    slab_over(sigma_a, sigma_s, g, depth, travel, irradiance, 0.0)
}

/// [`slab_file`] over a Lambertian floor of albedo `floor` (linear).
fn slab_over(
    sigma_a: [f32; 3],
    sigma_s: [f32; 3],
    g: f32,
    depth: f32,
    travel: Vec3,
    irradiance: f32,
    floor: f32,
) -> Vec<u8> {
    let mut scene = scene_of(&square(-0.5, 60.0));
    scene.materials[0].gpu = lambert_material([floor; 3]);
    scene.lights.push(light(LightKind::Directional, [0.0; 3], travel.to_array(), irradiance));
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.media.push(Medium {
        bounds: Bounds { min: [-50.0, 0.0, -50.0], max: [50.0, depth, 50.0] },
        sigma_a,
        sigma_s,
        g,
    });
    let cam = Pinhole::new([0.0, 8.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 60.0, W, H);
    scene.cameras.push(cam.file_camera());
    scene.orthographic.push(OrthographicCamera { camera: 0, xmag: 0.5 * W as f32 / H as f32, ymag: 0.5 });
    compile(scene, kiln_compiler::settings::Settings { media_volume_res: 4, ..fast_settings() })
}

/// The mean of an image.
fn mean(rgb: &[f32]) -> [f64; 3] {
    let mut mean = [0.0f64; 3];
    let n = (rgb.len() / 3) as f64;
    for p in rgb.chunks_exact(3) {
        for c in 0..3 {
            mean[c] += p[c] as f64 / n;
        }
    }
    mean
}

/// [`slab_file`] rendered by the reference path tracer at `bounces` = 1 (light scattered once):
/// the image's mean.
fn slab(sigma_a: [f32; 3], sigma_s: [f32; 3], g: f32, depth: f32, travel: Vec3, irradiance: f32) -> [f64; 3] {
    let dir = tempfile::tempdir().unwrap();
    let bytes = slab_file(sigma_a, sigma_s, g, depth, travel, irradiance);
    let file = dir.path().join("slab.kiln");
    std::fs::write(&file, &bytes).unwrap();
    let o = Options::new(&file, W, H).build();
    let sampling = Sampling { spp: 256, seed: DEFAULT_SEED, bounces: 1, progress: false };
    let (_, rgb) = render_with(&o, sampling, std::time::Instant::now()).expect("reference render");
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0), "NaN, Inf or < 0 in the image");
    mean(&rgb)
}

/// Single scattering towards the camera (+y) at depth s below the top of the slab: light
/// attenuated over s/μ on its way in (μ = |travel.y|) and over s on its way out, integrated over
/// the slab: σs p(θ) E (1 − e^{−σt D (1 + 1/μ)}) / (σt (1 + 1/μ)), cos θ = travel · (+y).
fn single_scattering(sigma_a: f64, sigma_s: f64, g: f64, depth: f64, travel: Vec3, irradiance: f64) -> f64 {
    let sigma_t = sigma_a + sigma_s;
    let mu = -travel.y as f64;
    let k = sigma_t * (1.0 + 1.0 / mu);
    sigma_s * henyey_greenstein(g, travel.y as f64) * irradiance * (1.0 - (-k * depth).exp()) / k
}

#[test]
fn single_scattering_in_a_lit_slab_matches_the_closed_form() {
    if !vulkan() {
        return;
    }
    // The haze, and an isotropic medium.
    let travel = Vec3::from_array(TRAVEL);
    for (sigma_a, sigma_s, g) in [(HAZE.sigma_a, HAZE.sigma_s, HAZE.g), ([0.0; 3], [0.5; 3], 0.0)] {
        let (depth, irradiance) = (HAZE.depth, HAZE.irradiance);
        let got = slab(sigma_a, sigma_s, g, depth, travel, irradiance);
        for c in 0..3 {
            let want = single_scattering(
                sigma_a[c] as f64,
                sigma_s[c] as f64,
                g as f64,
                depth as f64,
                travel,
                irradiance as f64,
            );
            let rel = (got[c] - want).abs() / want;
            eprintln!("slab σa {sigma_a:?} σs {sigma_s:?} g {g}: channel {c}: {:.6} vs {want:.6}", got[c]);
            assert!(
                rel < 0.01,
                "σa {sigma_a:?}, σs {sigma_s:?}, g {g}: channel {c}: {:.6} vs the closed form {want:.6} ({:.2} %)",
                got[c],
                rel * 100.0
            );
        }
    }
}

/// The same slab through `--media march`: the image's mean within 1 % of the closed form, every
/// pixel within a step's variation of it (the 4 × 4 interleaved step offsets).
#[test]
fn the_ray_march_matches_single_scattering_in_a_lit_slab() {
    if !vulkan() {
        return;
    }
    let travel = Vec3::from_array(TRAVEL);
    let Haze { sigma_a, sigma_s, g, depth, irradiance } = HAZE;
    let dir = tempfile::tempdir().unwrap();
    let bytes = slab_file(sigma_a, sigma_s, g, depth, travel, irradiance);
    let want: Vec<f64> = (0..3)
        .map(|c| {
            single_scattering(
                sigma_a[c] as f64,
                sigma_s[c] as f64,
                g as f64,
                depth as f64,
                travel,
                irradiance as f64,
            )
        })
        .collect();
    for steps in [16u32, 64] {
        let (rgb, _) = render(dir.path(), &format!("march{steps}"), &bytes, |f| {
            Options::new(f, W, H).unshadowed().media_march(steps)
        });
        let got = mean(&rgb);
        for c in 0..3 {
            let rel = (got[c] - want[c]).abs() / want[c];
            eprintln!("march {steps} steps: channel {c}: mean {:.6} vs {:.6}", got[c], want[c]);
            assert!(
                rel < 0.01,
                "{steps} steps: channel {c}: mean {:.6} vs the closed form {:.6}",
                got[c],
                want[c]
            );
            // A pixel samples the light-side attenuation e^{−σt·s/μ} at one point of each step,
            // so it may stray by up to its change over a step, σt·h/μ (h the step length).
            let h = depth as f64 / steps as f64;
            let stray = 0.01 + (sigma_a[c] + sigma_s[c]) as f64 * h / -travel.y as f64;
            for p in rgb.chunks_exact(3) {
                let rel = (p[c] as f64 - want[c]).abs() / want[c];
                assert!(
                    rel < stray,
                    "{steps} steps: channel {c}: a pixel of {} vs {:.6} (beyond {stray:.3})",
                    p[c],
                    want[c]
                );
            }
        }
    }
    // Without the technique, the black floor under a clear sky.
    let (rgb, _) = render(dir.path(), "none", &bytes, |f| Options::new(f, W, H).unshadowed());
    assert!(rgb.iter().all(|&v| v == 0.0), "the slab shows without --media march");
}

/// Light straight down into a slab (|x|, |z| < 10, 0 < y < 1.5), half of it under an opaque
/// roof (x < 0, y = 3); the camera inside the medium, looking along −z through the slab
/// (orthographic, 1 unit high): where the roof shades the medium nothing scatters, on the lit
/// side every pixel matches the closed form for its height, σs p(90°) E e^{−σt·(1.5 − y)}
/// (1 − e^{−σt·19.5}) / σt. The light is off screen: the march needs no on-screen light.
#[test]
fn the_ray_march_shows_the_volumetric_shadow_of_an_occluder() {
    if !vulkan() {
        return;
    }
    let (sigma_a, sigma_s, g, irradiance) = ([0.05f32, 0.1, 0.02], [0.2f32, 0.3, 0.5], 0.3f32, 2.0f32);
    let mut tris = square(-0.5, 12.0).to_vec();
    // The roof: x in [−12, 0], facing down, above the slab.
    let p = |x: f32, z: f32| Vec3::new(x, 3.0, z);
    tris.push([p(-12.0, -12.0), p(0.0, 12.0), p(-12.0, 12.0)]);
    tris.push([p(-12.0, -12.0), p(0.0, -12.0), p(0.0, 12.0)]);
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = lambert_material([0.0; 3]);
    scene.lights.push(light(LightKind::Directional, [0.0; 3], [0.0, -1.0, 0.0], irradiance));
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.media.push(Medium {
        bounds: Bounds { min: [-10.0, 0.0, -10.0], max: [10.0, 1.5, 10.0] },
        sigma_a,
        sigma_s,
        g,
    });
    let cam = Pinhole::new([0.0, 0.75, 9.5], [0.0, 0.75, 0.0], [0.0, 1.0, 0.0], 60.0, W, H);
    scene.cameras.push(cam.file_camera());
    let ymag = 0.5f32;
    let aspect = W as f32 / H as f32;
    scene.orthographic.push(OrthographicCamera { camera: 0, xmag: ymag * aspect, ymag });
    let bytes = compile(scene, kiln_compiler::settings::Settings { media_volume_res: 64, ..fast_settings() });
    let dir = tempfile::tempdir().unwrap();
    let (rgb, _) = render(dir.path(), "roof", &bytes, |f| Options::new(f, W, H).unshadowed().media_march(32));
    let (mut lit, mut shaded) = (0, 0);
    for py in 0..H {
        for px in 0..W {
            let x = ((px as f32 + 0.5) / W as f32 * 2.0 - 1.0) * ymag * aspect;
            let y = 0.75 + (1.0 - (py as f32 + 0.5) / H as f32 * 2.0) * ymag;
            let i = ((py * W + px) * 3) as usize;
            for c in 0..3 {
                let sigma_t = (sigma_a[c] + sigma_s[c]) as f64;
                let want = sigma_s[c] as f64
                    * henyey_greenstein(g as f64, 0.0)
                    * irradiance as f64
                    * (-sigma_t * (1.5 - y as f64)).exp()
                    * (1.0 - (-sigma_t * 19.5).exp())
                    / sigma_t;
                let got = rgb[i + c] as f64;
                // A volume cell is 20/64 units wide: stay a cell and a half from the roof's edge.
                if x > 0.47 {
                    assert!(
                        (got - want).abs() / want < 0.02,
                        "lit pixel ({px}, {py}) channel {c}: {got} vs {want}"
                    );
                    lit += 1;
                } else if x < -0.47 {
                    assert!(got < 0.01 * want, "shaded pixel ({px}, {py}) channel {c}: {got} (lit: {want})");
                    shaded += 1;
                }
            }
        }
    }
    assert!(lit > 100 && shaded > 100, "{lit} lit and {shaded} shaded pixel channels checked");
}

/// A grey floor under the lit slab through `--media march`: its light crosses the slab twice,
/// dimmed on the way in (depth/μ) and on the way out (depth), and the slab's single scattering
/// adds: albedo/π · E μ e^{−σt·D(1 + 1/μ)} + the closed form above, per channel.
#[test]
fn the_ray_march_dims_the_light_that_reaches_surfaces_through_the_medium() {
    if !vulkan() {
        return;
    }
    let travel = Vec3::from_array(TRAVEL);
    let Haze { sigma_a, sigma_s, g, depth, irradiance } = HAZE;
    // An albedo the G-buffer's 8-bit sRGB target holds exactly.
    let albedo = crate::harness::srgb8(188);
    let bytes = slab_over(sigma_a, sigma_s, g, depth, travel, irradiance, albedo);
    let dir = tempfile::tempdir().unwrap();
    let (rgb, _) =
        render(dir.path(), "floor", &bytes, |f| Options::new(f, W, H).unshadowed().media_march(64));
    let got = mean(&rgb);
    let mu = -travel.y as f64;
    for c in 0..3 {
        let sigma_t = (sigma_a[c] + sigma_s[c]) as f64;
        let surface = albedo as f64 / std::f64::consts::PI
            * irradiance as f64
            * mu
            * (-sigma_t * depth as f64 * (1.0 + 1.0 / mu)).exp();
        let want = surface
            + single_scattering(
                sigma_a[c] as f64,
                sigma_s[c] as f64,
                g as f64,
                depth as f64,
                travel,
                irradiance as f64,
            );
        eprintln!("floor channel {c}: {:.6} vs {want:.6} (surface {surface:.6})", got[c]);
        assert!(
            (got[c] - want).abs() / want < 0.01,
            "channel {c}: {:.6} vs the closed form {want:.6}",
            got[c]
        );
    }
}
