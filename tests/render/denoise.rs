//! The denoiser (`--denoise svgf`) on emissive quads over a diffuse floor (`emitters.rs`), whose
//! direct light is the closed-form polygon irradiance, estimated by RIS (independent noise in
//! every pixel):
//! - a flat-lit floor (a 16 × 16 emissive ceiling one unit above it, the camera beneath), one
//!   frame of 32 candidates: the floor's mean stays the closed form's, its noise falls by at
//!   least 4× and by no more than averaging over the filter's whole kernel could (Σ w² of the
//!   composed à-trous kernel, computed here by convolution);
//! - a black block one unit above the lit floor (its direct light is 0; light bleeding into it
//!   across the depth edge would show, scaled by the black surface's demodulator, 0.05): its
//!   pixels stay 0;
//! - many frames with an occluder casting a penumbra: the denoised image converges to the
//!   undenoised one pixel by pixel (the filter fades as the running mean's variance falls), and
//!   the floor to the closed form where the occluder does not shadow it.
//!
//! Where the light varies over the filter's reach (the small lamp's floor, 2 units below it),
//! one frame comes out 3 % dark (measured 0.971 of the closed form with 1 to 16 candidates):
//! SVGF's edge-stopping blurs the light's peak into its darker surroundings. It fades as the
//! frames accumulate (the second test).

use glam::{DVec3, Vec3};
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile};

use crate::emitters::{Quad, camera, quad_scene_with};
use crate::harness::{
    H, Pinhole, W, albedo, fast_settings, floor_pixels, pixel_xy, ratio_stats, render_frames, square,
};
use crate::rect::Rect;

/// Σ w² of `iterations` à-trous iterations of the separable kernel `taps` (weights at 0, ±1,
/// ±2, …), iteration i's taps 2^i pixels apart: how much averaging over the whole composed
/// kernel reduces the variance of independent noise.
fn atrous_power(taps: &[f64], iterations: u32) -> f64 {
    let mut kernel = vec![1.0f64];
    for i in 0..iterations {
        let step = 1usize << i;
        let r = taps.len() - 1;
        let mut next = vec![0.0; kernel.len() + 2 * r * step];
        for (j, &k) in kernel.iter().enumerate() {
            for (t, &w) in taps.iter().enumerate() {
                next[j + r * step + t * step] += k * w;
                if t > 0 {
                    next[j + r * step - t * step] += k * w;
                }
            }
        }
        kernel = next;
    }
    let one_axis: f64 = kernel.iter().map(|k| k * k).sum();
    one_axis * one_axis
}

/// Floor pixels of `cam` in front of `quad`, not hidden by it nor by `blocked`.
fn floor(cam: &Pinhole, quad: &Quad, blocked: impl Fn(DVec3, DVec3) -> bool) -> Vec<(usize, DVec3, DVec3)> {
    floor_pixels(cam, 9.5)
        .into_iter()
        .filter(|&(_, p, d)| quad.in_front(p) && !quad.crossed_by(cam.eye, d, 0.05) && !blocked(p, d))
        .collect()
}

/// The closed form a floor point under `quad` shows: albedo/π times the polygon irradiance.
fn lit(quad: &Quad) -> impl Fn(DVec3, DVec3) -> f64 + '_ {
    let a = albedo()[0];
    move |p, _| a / std::f64::consts::PI * quad.irradiance(p, 1.0)
}

/// A 16 × 16 ceiling of radiance 1 one unit above the floor, emitting downwards.
fn ceiling() -> Quad {
    let facing = DVec3::NEG_Y;
    let right = DVec3::Z;
    Quad(Rect {
        centre: DVec3::Y,
        facing,
        right,
        up: facing.cross(right),
        width: 16.0,
        height: 16.0,
        radiance: 1.0,
    })
}

/// Mean and variance of got / expected over floor `pixels` under `quad`.
fn ratios(rgb: &[f32], pixels: &[(usize, DVec3, DVec3)], quad: &Quad) -> (f64, f64) {
    let (mean, spread) = ratio_stats(rgb, pixels, lit(quad));
    (mean, spread * spread)
}

#[test]
fn svgf_keeps_a_flat_lit_floors_mean_and_cuts_its_noise() {
    let dir = gpu_test!();
    // Beneath the ceiling, looking down at the floor (the irradiance varies by under 3 % over
    // what it sees).
    let cam = Pinhole::new([0.0, 0.8, 2.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0], 60.0, W, H);
    let quad = ceiling();
    let bytes = compile(quad_scene_with(&cam, &quad, 1.0, false, &[], [0; 3]), fast_settings());
    // 32 candidates: one would draw points uniformly over the 256 m² ceiling, a noise so
    // heavy-tailed (per-pixel variance 26 × the mean²) that neither image's mean is its
    // expectation (raw 0.971, svgf 0.717: SVGF's edge-stopping drops the rare huge samples).
    let noisy = |o: Options| o.rt_shadows(0.0, 0.0).ris(32);
    let (raw, _) = render_frames(dir.path(), "flat-raw", &bytes, 1, |f| noisy(Options::new(f, W, H)));
    let (den, _) =
        render_frames(dir.path(), "flat-svgf", &bytes, 1, |f| noisy(Options::new(f, W, H)).svgf(5, 3));
    let pixels = floor(&cam, &quad, |_, _| false);
    let (raw_mean, raw_var) = ratios(&raw, &pixels, &quad);
    let (mean, var) = ratios(&den, &pixels, &quad);
    let bound = atrous_power(&[0.5, 0.25], 5);
    eprintln!(
        "flat floor ({} pixels): raw mean ratio {raw_mean:.4} variance {raw_var:.4}; svgf {mean:.4} {var:.5}: \
         noise variance / {:.1} (whole-kernel averaging: / {:.1})",
        pixels.len(),
        raw_var / var,
        1.0 / bound
    );
    assert!(pixels.len() > (W * H / 2) as usize, "only {} floor pixels", pixels.len());
    assert!((mean - 1.0).abs() < 0.005, "the denoised floor's mean ratio is {mean} (raw {raw_mean})");
    assert!(raw_var / var >= 4.0, "the noise variance fell only {:.2}×", raw_var / var);
    assert!(
        var >= 0.5 * bound * raw_var,
        "the noise fell {:.0}×: more than the kernel averages",
        raw_var / var
    );
}

/// A square of half-side 0.6 at height 1 under the lamp (its shadow on the floor has a
/// penumbra).
pub(crate) fn occluder() -> Vec<[Vec3; 3]> {
    square(1.0, 0.6).iter().map(|t| t.map(|p| p + Vec3::new(0.9, 0.0, -0.3))).collect()
}

#[test]
fn svgf_bleeds_no_floor_light_into_a_black_block() {
    let dir = gpu_test!();
    let (cam, quad) = (camera(), Quad::new());
    let bytes = compile(quad_scene_with(&cam, &quad, 1.0, false, &occluder(), [0; 3]), fast_settings());
    let noisy = |o: Options| o.rt_shadows(0.0, 0.0).ris(1);
    let (raw, _) = render_frames(dir.path(), "edge-raw", &bytes, 1, |f| noisy(Options::new(f, W, H)));
    let (den, _) =
        render_frames(dir.path(), "edge-svgf", &bytes, 1, |f| noisy(Options::new(f, W, H)).svgf(5, 3));
    // The floor's brightest, against which a bleed is measured.
    let peak = floor(&cam, &quad, |_, _| false).iter().map(|&(_, p, d)| lit(&quad)(p, d)).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    let mut block = 0;
    for y in 0..H {
        for x in 0..W {
            // Pixels whose ray meets the block's top well inside its edges.
            let d = cam.ray(x, y, W, H);
            let q = cam.eye + d * ((1.0 - cam.eye.y) / d.y);
            if (q.x - 0.9).abs() < 0.55 && (q.z + 0.3).abs() < 0.55 {
                let i = ((y * W + x) * 3) as usize;
                assert_eq!(raw[i], 0.0, "block pixel ({x}, {y}) is not black undenoised");
                worst = worst.max(den[i] as f64 / peak);
                block += 1;
            }
        }
    }
    eprintln!("black block ({block} pixels): brightest denoised {worst:.5} of the floor's peak {peak:.3}");
    assert!(block > 30, "only {block} block pixels");
    // A bleed of the floor's light would show as up to 0.05 of the peak (the demodulator).
    assert!(worst < 0.002, "a block pixel shows {worst:.4} of the floor's peak: light bled across the edge");
}

#[test]
fn svgf_converges_to_the_undenoised_image_and_the_closed_form() {
    let dir = gpu_test!();
    let cam = camera();
    // A square occluder at height 1 under the lamp casts a penumbra onto the floor: detail the
    // filter must stop blurring as the frames accumulate.
    let quad = Quad::new();
    let bytes = compile(
        quad_scene_with(&cam, &quad, 1.0, false, &occluder(), crate::harness::ALBEDO),
        fast_settings(),
    );
    let frames = 96;
    let opts = |o: Options| o.rt_shadows(0.0, 0.0).ris(16);
    let (raw, _) = render_frames(dir.path(), "conv-raw", &bytes, frames, |f| opts(Options::new(f, W, H)));
    let (den, _) =
        render_frames(dir.path(), "conv-svgf", &bytes, frames, |f| opts(Options::new(f, W, H)).svgf(5, 3));
    // Pixel by pixel: the two running means differ by their noise alone (measured at most 3.1 %
    // of the floor's brightest; a filter that does not fade, its variance not divided by the
    // samples averaged, blurs the penumbra by 14 %), wherever the penumbra lies.
    let peak = raw.iter().step_by(3).fold(0.0f32, |m, &v| if v < 3.0 { m.max(v) } else { m }) as f64;
    let mut worst = (0.0f64, 0, 0);
    for i in (0..raw.len()).step_by(3) {
        let d = (den[i] as f64 - raw[i] as f64).abs() / peak;
        if d > worst.0 {
            let (x, y) = pixel_xy(i);
            worst = (d, x, y);
        }
    }
    eprintln!(
        "svgf against raw at {frames} frames: worst {:.4} of the floor's peak at ({}, {})",
        worst.0, worst.1, worst.2
    );
    assert!(worst.0 < 0.05, "pixel ({}, {}) differs by {:.3} of the peak", worst.1, worst.2, worst.0);
    // Where the occluder hides no part of the lamp (its shadow volume with a wide margin), the
    // floor's mean is the closed form's to 0.5 %.
    let shadowed = |p: DVec3, d: DVec3| {
        let near_occluder = (p.x - 0.9).abs() < 3.0 && (p.z + 0.3).abs() < 2.0;
        let behind = {
            let t = (1.0 - cam.eye.y) / d.y;
            let q = cam.eye + d * t;
            (q.x - 0.9).abs() < 0.65 && (q.z + 0.3).abs() < 0.65
        };
        near_occluder || behind
    };
    let pixels = floor(&cam, &quad, shadowed);
    let (mean, _) = ratios(&den, &pixels, &quad);
    eprintln!("unshadowed floor ({} pixels): mean ratio {mean:.5}", pixels.len());
    assert!(pixels.len() > 1000, "only {} pixels", pixels.len());
    assert!((mean - 1.0).abs() < 0.005, "the converged floor's mean ratio is {mean}");
}
