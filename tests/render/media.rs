//! Participating media in the reference path tracer against closed forms. (Against an
//! independent renderer with multiple scattering: `tests/mitsuba.rs`, the room full of fog.)

use glam::Vec3;
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::{Bounds, LightKind, Medium, OrthographicCamera, Sky};
use kiln_player::reference::{DEFAULT_SEED, Sampling, render_with};
use kiln_tests::{Options, compile, scene_of, vulkan};

use crate::harness::{Pinhole, fast_settings, light, square};

const W: u32 = 32;
const H: u32 = 24;

/// Henyey–Greenstein, written out here: (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}).
fn henyey_greenstein(g: f64, cos_theta: f64) -> f64 {
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * cos_theta).powf(1.5))
}

/// Straight down through a slab of medium (|x|, |z| < 50, 0 < y < `depth`) onto a black floor,
/// through an orthographic camera 1 unit wide: every pixel's ray crosses the slab far from its
/// sides. The mean of the image at `bounces` = 1 (light scattered once).
fn slab(sigma_a: [f32; 3], sigma_s: [f32; 3], g: f32, depth: f32, travel: Vec3, irradiance: f32) -> [f64; 3] {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = scene_of(&square(-0.5, 60.0));
    scene.materials[0].gpu = lambert_material([0.0; 3]);
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
    let bytes = compile(scene, kiln_compiler::settings::Settings { media_volume_res: 4, ..fast_settings() });
    let file = dir.path().join("slab.kiln");
    std::fs::write(&file, &bytes).unwrap();
    let o = Options::new(&file, W, H).build();
    let sampling = Sampling { spp: 256, seed: DEFAULT_SEED, bounces: 1, progress: false };
    let (_, rgb) = render_with(&o, sampling, std::time::Instant::now()).expect("reference render");
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0), "NaN, Inf or < 0 in the image");
    let mut mean = [0.0f64; 3];
    for p in rgb.chunks_exact(3) {
        for c in 0..3 {
            mean[c] += p[c] as f64 / (W * H) as f64;
        }
    }
    mean
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
    // Chromatic coefficients (optical depths 0.3 to 1.35 across the slab), forward scattering
    // seen from behind the light's travel (cos θ = −0.6), and an isotropic case.
    let travel = Vec3::new(0.8, -0.6, 0.0);
    for (sigma_a, sigma_s, g) in
        [([0.1f32, 0.2, 0.05], [0.1f32, 0.4, 0.85], 0.5f32), ([0.0; 3], [0.5; 3], 0.0)]
    {
        let (depth, irradiance) = (1.5f32, 4.0f32);
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
