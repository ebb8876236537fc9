//! Participating media against closed forms: the reference path tracer, `--media march` and
//! `--media toth`. (The image-space techniques: `godrays.rs`.)
//! (The reference against an independent renderer with multiple scattering: `tests/mitsuba.rs`,
//! the room full of fog.)

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::{Bounds, LightKind, Medium, OrthographicCamera, Sky};
use kiln_player::reference::{DEFAULT_SEED, Sampling, render_with};
use kiln_player::render::Media;
use kiln_player::render::techniques;
use kiln_player::render::techniques::media::toth::Phase;
use kiln_test_support::{gpu_test, require, vulkan};
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{Pinhole, fast_settings, light, render, square};

pub const W: u32 = 32;
pub const H: u32 = 24;

/// The slab's medium and light: chromatic coefficients (optical depths 0.3 to 1.35 across the
/// slab), forward scattering seen from behind the light's travel.
pub struct Haze {
    pub sigma_a: [f32; 3],
    pub sigma_s: [f32; 3],
    pub g: f32,
    pub depth: f32,
    pub irradiance: f32,
}

pub const HAZE: Haze =
    Haze { sigma_a: [0.1, 0.2, 0.05], sigma_s: [0.1, 0.4, 0.85], g: 0.5, depth: 1.5, irradiance: 4.0 };

/// The light's direction of travel (cos θ = −0.6 towards a camera looking straight down).
pub const TRAVEL: [f32; 3] = [0.8, -0.6, 0.0];

/// Henyey–Greenstein, written out here: (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}).
pub fn henyey_greenstein(g: f64, cos_theta: f64) -> f64 {
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * cos_theta).powf(1.5))
}

/// Straight down through a slab of medium (|x|, |z| < 50, 0 < y < `depth`) onto a black floor,
/// through an orthographic camera 1 unit wide: every pixel's ray crosses the slab far from its
/// sides. The file's bytes.
pub fn slab_file(
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
    let sun = light(LightKind::Directional, [0.0; 3], travel.to_array(), irradiance);
    let medium = slab_medium(sigma_a, sigma_s, g, depth);
    slab_lit_by(sun, medium, floor, 4)
}

/// The slab: |x|, |z| < 50, 0 < y < `depth`.
fn slab_medium(sigma_a: [f32; 3], sigma_s: [f32; 3], g: f32, depth: f32) -> Medium {
    Medium { bounds: Bounds { min: [-50.0, 0.0, -50.0], max: [50.0, depth, 50.0] }, sigma_a, sigma_s, g }
}

/// Half the width and half the height of the slab scenes' orthographic view.
const SLAB_XMAG: f32 = 0.5 * W as f32 / H as f32;
const SLAB_YMAG: f32 = 0.5;

/// The slab scene: `medium` over a Lambertian floor of albedo `floor` at y = −0.5, lit by
/// `light` under a black sky, seen straight down through the orthographic camera; the light's
/// visibility volume `volume_res` cells on its longest axis.
fn slab_lit_by(light: kiln_format::manifest::Light, medium: Medium, floor: f32, volume_res: u32) -> Vec<u8> {
    let mut scene = scene_of(&square(-0.5, 60.0));
    scene.materials[0].gpu = lambert_material([floor; 3]);
    scene.lights.push(light);
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.media.push(medium);
    let cam = Pinhole::new([0.0, 8.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 60.0, W, H);
    scene.cameras.push(cam.file_camera());
    scene.orthographic.push(OrthographicCamera { camera: 0, xmag: SLAB_XMAG, ymag: SLAB_YMAG });
    compile(scene, kiln_compiler::settings::Settings { media_volume_res: volume_res, ..fast_settings() })
}

/// The mean of an image.
pub fn mean(rgb: &[f32]) -> [f64; 3] {
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
/// the slab: σs p(θ) E (1 − e^{−σt D (1 + 1/μ)}) / (σt (1 + 1/μ)), cos θ = travel · (+y), with
/// the Henyey–Greenstein phase function of anisotropy `g`.
fn single_scattering(sigma_a: f64, sigma_s: f64, g: f64, depth: f64, travel: Vec3, irradiance: f64) -> f64 {
    scattered_with(sigma_a, sigma_s, henyey_greenstein(g, travel.y as f64), depth, travel, irradiance)
}

/// [`single_scattering`] with the phase function's value p(θ) given.
fn scattered_with(sigma_a: f64, sigma_s: f64, phase: f64, depth: f64, travel: Vec3, irradiance: f64) -> f64 {
    let sigma_t = sigma_a + sigma_s;
    let mu = -travel.y as f64;
    let k = sigma_t * (1.0 + 1.0 / mu);
    sigma_s * phase * irradiance * (1.0 - (-k * depth).exp()) / k
}

/// Rayleigh, written out here: 3/(16π) (1 + cos² θ).
fn rayleigh(cos_theta: f64) -> f64 {
    3.0 / (16.0 * std::f64::consts::PI) * (1.0 + cos_theta * cos_theta)
}

#[test]
fn single_scattering_in_a_lit_slab_matches_the_closed_form() {
    require!(vulkan());
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
    let dir = gpu_test!();
    let travel = Vec3::from_array(TRAVEL);
    let Haze { sigma_a, sigma_s, g, depth, irradiance } = HAZE;
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
/// (1 − e^{−σt·19.5}) / σt. The light is off screen: the world-space marches need no on-screen
/// light. Both `march` (the baked visibility volume) and `toth` (the shadow map).
#[test]
fn the_marches_show_the_volumetric_shadow_of_an_occluder() {
    let dir = gpu_test!();
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
    // The ray march reads the light's visibility from the baked volume, toth from the shadow map
    // (shadows on the surfaces off: the pass binds the maps itself).
    let toth = Media::Toth(techniques::media::toth::Toth { samples: 64, block: 4, phase: Phase::Medium });
    for media in [Media::March(techniques::media::march::March { steps: 32 }), toth] {
        let (rgb, _) =
            render(dir.path(), "roof", &bytes, |f| Options::new(f, W, H).unshadowed().media(media));
        // toth's blur window is moved inside the image at its border: there it averages
        // rows up to 4 away, across the light's vertical gradient; skip its 2-pixel border.
        let border = if media == toth { 2 } else { 0 };
        roof_shadow(&rgb, (sigma_a, sigma_s, g, irradiance), ymag, aspect, border, &format!("{media:?}"));
    }
}

/// The roof test's per-pixel check of one image.
fn roof_shadow(
    rgb: &[f32],
    medium: ([f32; 3], [f32; 3], f32, f32),
    ymag: f32,
    aspect: f32,
    border: u32,
    what: &str,
) {
    let (sigma_a, sigma_s, g, irradiance) = medium;
    let (mut lit, mut shaded) = (0, 0);
    for py in border..H - border {
        for px in border..W - border {
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
                        "{what}: lit pixel ({px}, {py}) channel {c}: {got} vs {want}"
                    );
                    lit += 1;
                } else if x < -0.47 {
                    assert!(
                        got < 0.01 * want,
                        "{what}: shaded pixel ({px}, {py}) channel {c}: {got} (lit: {want})"
                    );
                    shaded += 1;
                }
            }
        }
    }
    assert!(lit > 100 && shaded > 100, "{what}: {lit} lit and {shaded} shaded pixel channels checked");
}

/// A grey floor under the lit slab through `--media march`: its light crosses the slab twice,
/// dimmed on the way in (depth/μ) and on the way out (depth), and the slab's single scattering
/// adds: albedo/π · E μ e^{−σt·D(1 + 1/μ)} + the closed form above, per channel.
#[test]
fn the_ray_march_dims_the_light_that_reaches_surfaces_through_the_medium() {
    let dir = gpu_test!();
    let travel = Vec3::from_array(TRAVEL);
    let Haze { sigma_a, sigma_s, g, depth, irradiance } = HAZE;
    // An albedo the G-buffer's 8-bit sRGB target holds exactly.
    let albedo = crate::harness::srgb8(188);
    let bytes = slab_over(sigma_a, sigma_s, g, depth, travel, irradiance, albedo);
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

/// The slab through `--media toth`: 60 midpoint samples interleaved over 4 × 4 pixels and
/// blurred back together, the light's visibility from its baked shadow map. Every pixel at
/// least two from the border (where the blur's window holds every sample set) is within 1 % of
/// the closed form, for the medium's Henyey–Greenstein and for Rayleigh. The closed forms use
/// the normalised phase functions, so one that does not integrate to 1 over the sphere (the
/// seed's listings: HG with (1 − g)², "Rayleigh" as cos² θ) fails, as does the listing's missing
/// Δs factor.
#[test]
fn the_shadow_map_march_matches_single_scattering_in_a_lit_slab() {
    let dir = gpu_test!();
    let Haze { sigma_a, sigma_s, g, depth, irradiance } = HAZE;
    // Two scattering angles (cos θ −0.6 and −0.96), so that a phase function with the right
    // value at one angle but the wrong shape fails too.
    for travel in [Vec3::from_array(TRAVEL), Vec3::new(0.28, -0.96, 0.0)] {
        let bytes = slab_file(sigma_a, sigma_s, g, depth, travel, irradiance);
        let cos_theta = travel.y as f64;
        for (phase, p) in
            [(Phase::Medium, henyey_greenstein(g as f64, cos_theta)), (Phase::Rayleigh, rayleigh(cos_theta))]
        {
            // 60 samples over 16 pixels: some pixels take 4, some 3, and every sample must still
            // count once.
            let media = Media::Toth(techniques::media::toth::Toth { samples: 60, block: 4, phase });
            let (rgb, _) = render(dir.path(), &format!("toth {phase:?}"), &bytes, |f| {
                Options::new(f, W, H).media(media)
            });
            for c in 0..3 {
                let want = scattered_with(
                    sigma_a[c] as f64,
                    sigma_s[c] as f64,
                    p,
                    depth as f64,
                    travel,
                    irradiance as f64,
                );
                eprintln!("toth {phase:?}: channel {c}: mean {:.6} vs {want:.6}", mean(&rgb)[c]);
                for y in 2..H - 2 {
                    for x in 2..W - 2 {
                        let got = rgb[((y * W + x) * 3) as usize + c] as f64;
                        assert!(
                            (got - want).abs() / want < 0.01,
                            "{phase:?}: pixel ({x}, {y}) channel {c}: {got:.6} vs the closed form {want:.6}"
                        );
                    }
                }
            }
        }
    }
}

/// A point light 1.5 units above the lit slab (inverse-square falloff, the scattering angle and
/// the light-side path changing along every view ray, its cube shadow map read at every sample):
/// each pixel's single scattering is the integral over the slab's depth of
/// σs p(θ) I/d² e^{−σt·ℓ_light} e^{−σt·(D − y)}, summed here by a 4000-step midpoint rule. `toth`
/// without interleaving (60 samples) matches it per pixel within 1 %; `march` (64 steps, its
/// source at a jittered point of each step) in the image's mean.
#[test]
fn the_marches_match_single_scattering_from_a_point_light() {
    let dir = gpu_test!();
    let Haze { sigma_a, sigma_s, g, depth, .. } = HAZE;
    let (lamp, intensity) = (DVec3::new(0.3, depth as f64 + 1.5, 0.2), 20.0f64);
    let lamp_light = light(LightKind::Point, lamp.as_vec3().to_array(), [0.0, -1.0, 0.0], intensity as f32);
    let medium = slab_medium(sigma_a, sigma_s, g, depth);
    let bytes = slab_lit_by(lamp_light, medium, 0.0, 8);
    let (xmag, ymag) = (SLAB_XMAG, SLAB_YMAG);
    // The expected image: straight down through pixel (px, py) at x, z.
    let expected = |px: u32, py: u32, c: usize| {
        let x = ((px as f64 + 0.5) / W as f64 * 2.0 - 1.0) * xmag as f64;
        let z = -(1.0 - (py as f64 + 0.5) / H as f64 * 2.0) * ymag as f64;
        let sigma_t = (sigma_a[c] + sigma_s[c]) as f64;
        let d_slab = depth as f64;
        let steps = 4000;
        let dy = d_slab / steps as f64;
        (0..steps)
            .map(|i| {
                let y = (i as f64 + 0.5) * dy;
                let to = lamp - DVec3::new(x, y, z);
                let d = to.length();
                // The part of the way to the lamp below the slab's top.
                let inside = d * (d_slab - y) / (lamp.y - y);
                let cos_theta = -to.y / d;
                sigma_s[c] as f64 * henyey_greenstein(g as f64, cos_theta) * intensity / (d * d)
                    * (-sigma_t * inside).exp()
                    * (-sigma_t * (d_slab - y)).exp()
                    * dy
            })
            .sum::<f64>()
    };
    let toth = Media::Toth(techniques::media::toth::Toth { samples: 60, block: 1, phase: Phase::Medium });
    let (rgb, _) = render(dir.path(), "toth point", &bytes, |f| Options::new(f, W, H).media(toth));
    let mut want_mean = [0.0f64; 3];
    for py in 0..H {
        for px in 0..W {
            for c in 0..3 {
                let want = expected(px, py, c);
                want_mean[c] += want / (W * H) as f64;
                let got = rgb[((py * W + px) * 3) as usize + c] as f64;
                assert!(
                    (got - want).abs() / want < 0.01,
                    "toth: pixel ({px}, {py}) channel {c}: {got:.6} vs {want:.6}"
                );
            }
        }
    }
    let (rgb, _) = render(dir.path(), "march point", &bytes, |f| {
        Options::new(f, W, H).media(Media::March(techniques::media::march::March { steps: 64 }))
    });
    let got = mean(&rgb);
    for c in 0..3 {
        eprintln!("point light: channel {c}: march mean {:.6} vs {:.6}", got[c], want_mean[c]);
        assert!(
            (got[c] - want_mean[c]).abs() / want_mean[c] < 0.01,
            "march: channel {c}: mean {:.6} vs {:.6}",
            got[c],
            want_mean[c]
        );
    }
}

/// The sky scattered by the ray march (format 1.10's sky grids): a slab (|x|, |z| < 10,
/// 0 < y < 1.5) over a black floor under a uniform sky L, no light, seen straight down. Single
/// scattering of a uniform sky: at depth s below the slab's top the medium sees the upper
/// hemisphere's sky through e^{−σt s/μ} of itself (the floor hides the lower one), whatever the
/// phase function: (1/4π) ∫ L e^{−σt s/μ} dω = L E₂(σt s) / 2, E₂ the exponential integral
/// ∫₀¹ e^{−x/μ} dμ (summed here by the midpoint rule); the camera sees
/// ∫₀ᴰ σs L E₂(σt s)/2 · e^{−σt s} ds. The image's mean within 1.5 % per channel (the grids hold
/// 32 stratified directions per cell, 10 cells through the depth, trilinear between them).
#[test]
fn the_ray_march_scatters_the_sky_in_a_slab() {
    let dir = gpu_test!();
    let (sigma_a, sigma_s, g, depth) = ([0.1f32, 0.2, 0.05], [0.4f32, 0.6, 0.8], 0.5f32, 1.5f32);
    let sky = [1.0f32, 0.5, 0.25];
    let mut scene = scene_of(&square(-0.5, 60.0));
    scene.materials[0].gpu = lambert_material([0.0; 3]);
    scene.sky = Sky { radiance: sky };
    scene.media.push(Medium {
        bounds: Bounds { min: [-10.0, 0.0, -10.0], max: [10.0, depth, 10.0] },
        sigma_a,
        sigma_s,
        g,
    });
    let cam = Pinhole::new([0.0, 8.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 60.0, W, H);
    scene.cameras.push(cam.file_camera());
    scene.orthographic.push(OrthographicCamera { camera: 0, xmag: SLAB_XMAG, ymag: SLAB_YMAG });
    let bytes =
        compile(scene, kiln_compiler::settings::Settings { media_volume_res: 128, ..fast_settings() });
    let e2 = |x: f64| {
        let n = 4000;
        (0..n).map(|i| (-x / ((i as f64 + 0.5) / n as f64)).exp()).sum::<f64>() / n as f64
    };
    let want: Vec<f64> = (0..3)
        .map(|c| {
            let (st, ss, l) = ((sigma_a[c] + sigma_s[c]) as f64, sigma_s[c] as f64, sky[c] as f64);
            let n = 600;
            let h = depth as f64 / n as f64;
            (0..n)
                .map(|i| {
                    let s = (i as f64 + 0.5) * h;
                    ss * l * 0.5 * e2(st * s) * (-st * s).exp() * h
                })
                .sum()
        })
        .collect();
    let (rgb, _) = render(dir.path(), "sky", &bytes, |f| Options::new(f, W, H).unshadowed().media_march(64));
    let got = mean(&rgb);
    for c in 0..3 {
        eprintln!("sky through the slab, channel {c}: mean {:.5} vs {:.5}", got[c], want[c]);
        assert!(
            (got[c] / want[c] - 1.0).abs() < 0.015,
            "channel {c}: the sky scattered {:.5}, the closed form {:.5}",
            got[c],
            want[c]
        );
    }
}

/// The sky's phase convolution through the environment's harmonics: an optically thin box
/// (σt · size ≤ 0.04, no geometry near it) under an environment L(ω) = 1 + 0.8 ω_y, seen straight
/// down with g = 0.6. Single scattering is then σs ∫ p(ω · d) L(ω) dω per unit length, and
/// Henyey–Greenstein scales the first harmonic band by g: 1 + 0.8 g d_y = 0.52 at d = −y (1.0
/// for an isotropic medium, 1.48 looking up); the camera sees the background (0.2, measured
/// without the medium: the baked map's E5B9G9R9 texels round it by more than the scattered light's
/// tolerance) through e^{−σt·2} and σs (1 − 0.8 g) (1 − e^{−σt·2}) / σt scattered. The scattered
/// part within 3 %.
#[test]
fn the_ray_march_scatters_an_environment_by_its_phase_function() {
    let dir = gpu_test!();
    let (sigma_s, g) = ([0.005f32, 0.01, 0.02], 0.6f32);
    // A small triangle well away from the box and the view: the scene needs geometry.
    let mut scene =
        scene_of(&[[Vec3::new(30.0, 0.0, 0.0), Vec3::new(30.1, 0.0, 0.0), Vec3::new(30.0, 0.1, 0.0)]]);
    scene.materials[0].gpu = lambert_material([0.0; 3]);
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.environment = Some(kiln_tests::equirect::image(256, |d| [1.0 + 0.8 * d[1]; 3]));
    scene.media.push(Medium {
        bounds: Bounds { min: [-1.0, 0.0, -1.0], max: [1.0, 2.0, 1.0] },
        sigma_a: [0.0; 3],
        sigma_s,
        g,
    });
    let cam = Pinhole::new([0.0, 8.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 60.0, W, H);
    scene.cameras.push(cam.file_camera());
    scene.orthographic.push(OrthographicCamera { camera: 0, xmag: SLAB_XMAG, ymag: SLAB_YMAG });
    let bytes = compile(scene, kiln_compiler::settings::Settings { media_volume_res: 16, ..fast_settings() });
    let (rgb, _) = render(dir.path(), "env", &bytes, |f| Options::new(f, W, H).unshadowed().media_march(64));
    let got = mean(&rgb);
    let (plain, _) = render(dir.path(), "env-none", &bytes, |f| Options::new(f, W, H).unshadowed());
    let plain = mean(&plain);
    for c in 0..3 {
        let st = sigma_s[c] as f64;
        let t = (-st * 2.0).exp();
        let background = plain[c] * t;
        let want = st * (1.0 - 0.8 * g as f64) * (1.0 - t) / st;
        let scattered = got[c] - background;
        eprintln!("environment through a thin box, channel {c}: scattered {scattered:.6} vs {want:.6}");
        assert!(
            (scattered / want - 1.0).abs() < 0.03,
            "channel {c}: the environment scattered {scattered:.6}, Henyey–Greenstein's convolution {want:.6}"
        );
    }
}
