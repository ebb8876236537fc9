//! The image-space god rays (`--media mitchell`, `--media sousa`, seed 002): Mitchell's blur
//! against its own definition computed here, Sousa's shafts where the sky is, and the known
//! failure of both, a light behind the camera, asserted next to the world-space techniques that
//! do show its light.

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::{Bounds, LightKind, Medium, Sky};
use kiln_player::render::techniques;
use kiln_player::render::techniques::media::toth::Phase;
use kiln_player::render::{Media, ScreenFraction};
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{Pinhole, fast_settings, light, render};
use crate::media::{H, W, henyey_greenstein, mean};

/// A thin haze around the camera and the wall (optical depths 0.5 to 2.1 across its 50 units
/// along z), forward scattering.
const FOG: Medium = Medium {
    bounds: Bounds { min: [-40.0, -40.0, -30.0], max: [40.0, 40.0, 20.0] },
    sigma_a: [0.005, 0.005, 0.01],
    sigma_s: [0.005, 0.02, 0.03],
    g: 0.5,
};

/// The sun's irradiance.
const SUN: f32 = 4.0;

/// The camera: at (0, 1, 10) looking along −z.
fn camera() -> Pinhole {
    Pinhole::new([0.0, 1.0, 10.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], 60.0, W, H)
}

/// A black wall in the plane z = −20 above y = 1 (the top half of the image), a black sky, the
/// fog around camera and wall, and the sun towards `to_sun`: what the image shows is the shafts
/// alone.
fn sky_over_wall(to_sun: Vec3) -> Vec<u8> {
    let p = |x: f32, y: f32| Vec3::new(x, y, -20.0);
    let wall = [
        [p(-200.0, 1.0), p(200.0, 1.0), p(200.0, 200.0)],
        [p(-200.0, 1.0), p(200.0, 200.0), p(-200.0, 200.0)],
    ];
    let mut scene = scene_of(&wall);
    scene.materials[0].gpu = lambert_material([0.0; 3]);
    scene.lights.push(light(LightKind::Directional, [0.0; 3], (-to_sun.normalize()).to_array(), SUN));
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.media.push(FOG);
    scene.cameras.push(camera().file_camera());
    compile(scene, kiln_compiler::settings::Settings { media_volume_res: 4, ..fast_settings() })
}

/// Above the camera's view axis, so that the light's image lies in the wall's (top) half: a
/// radial blur that mirrored the light vertically would see other rows.
const TO_SUN: [f32; 3] = [0.0, 0.11547, -1.0];

/// The radiance one unit of blur amount adds at the pixel looking along `d` (godrays.glsl's
/// definition written out): the sun's irradiance times the medium's albedo and its
/// Henyey–Greenstein phase at the angle between `d` and the sun.
fn shaft_radiance(d: DVec3, to_sun: DVec3) -> [f64; 3] {
    let Medium { sigma_a, sigma_s, g, .. } = FOG;
    let p = henyey_greenstein(g as f64, d.dot(to_sun.normalize()));
    std::array::from_fn(|c| SUN as f64 * sigma_s[c] as f64 / (sigma_a[c] + sigma_s[c]) as f64 * p)
}

/// Mitchell at full resolution, 60 samples, exposure 1.921: each pixel's amount is
/// (exposure / n) · (its own occlusion sample + the n samples at v − i (v − v_light) / (n · 1.4)),
/// the occlusion image 1 in the bottom (sky) rows and 0 in the top (wall) ones, read bilinearly
/// between row centres; every pixel within 1.5 % of that times the shaft radiance. Catches a
/// wrong step or density, a missing or doubled own sample, an exposure not divided by n, a
/// light mirrored vertically, and the scale.
#[test]
fn mitchells_blur_matches_its_definition() {
    let dir = gpu_test!();
    let to_sun = Vec3::from_array(TO_SUN);
    let bytes = sky_over_wall(to_sun);
    let (samples, exposure) = (60u32, 1.921f32);
    let media = Media::Mitchell(techniques::media::mitchell::Mitchell {
        samples,
        resolution: ScreenFraction::Full,
        exposure,
    });
    let (rgb, _) = render(dir.path(), "mitchell", &bytes, |f| Options::new(f, W, H).media(media));
    let cam = camera();
    let (_, v_light) = cam.project_direction(to_sun.as_dvec3()).expect("the sun is in front");
    assert!(v_light < 0.5, "the sun's image lies in the wall's half");
    // The occlusion image read bilinearly at v: rows whose centre lies below the image's middle
    // show the sky.
    let occlusion = |v: f64| {
        let f = (v * H as f64 - 0.5).clamp(0.0, H as f64 - 1.0);
        let (r0, w) = (f.floor(), f - f.floor());
        let sky = |r: f64| if r >= (H / 2) as f64 { 1.0 } else { 0.0 };
        (1.0 - w) * sky(r0) + w * sky((r0 + 1.0).min(H as f64 - 1.0))
    };
    let mut lit = 0;
    for y in 0..H {
        for x in 0..W {
            let v = (y as f64 + 0.5) / H as f64;
            let step = (v - v_light) / (samples as f64 * 1.4);
            let sum = occlusion(v) + (1..=samples).map(|i| occlusion(v - i as f64 * step)).sum::<f64>();
            let amount = exposure as f64 / samples as f64 * sum;
            let want = shaft_radiance(cam.ray(x, y, W, H), to_sun.as_dvec3()).map(|s| s * amount);
            for c in 0..3 {
                let got = rgb[((y * W + x) * 3) as usize + c] as f64;
                let scale = shaft_radiance(cam.ray(x, y, W, H), to_sun.as_dvec3())[c] * exposure as f64;
                assert!(
                    (got - want[c]).abs() <= 0.015 * scale,
                    "pixel ({x}, {y}) channel {c}: {got:.6} vs {:.6} (amount {amount:.4})",
                    want[c]
                );
            }
            lit += (amount > 0.1) as u32;
        }
    }
    assert!(lit > W * H / 3, "{lit} pixels show shafts");
}

/// Sousa (3 passes) in the same scene, at 6 taps (the seed's) and at 3: the far sky in the
/// bottom half is bright, the wall in the top half (a depth map of about 30 over the scene's
/// 566-unit diagonal) nearly dark, no amount exceeds the three passes' bound (6 · 0.19)³, and
/// 3 taps give about the same brightness as 6 (the brightness per sample is scaled by 6/TAPS;
/// without, 3 taps would be 8 times darker).
#[test]
fn sousas_shafts_come_from_the_far_sky() {
    let dir = gpu_test!();
    let to_sun = Vec3::from_array(TO_SUN);
    let bytes = sky_over_wall(to_sun);
    let cam = camera();
    let bound = (6.0f64 * 0.19).powi(3);
    let rows = (W * (H / 2 - 2)) as f64;
    let mut bottoms = Vec::new();
    for taps in [6, 3] {
        let media = Media::Sousa(techniques::media::sousa::Sousa {
            taps,
            resolution: ScreenFraction::Full,
            brightness: 0.19,
        });
        let (rgb, _) = render(dir.path(), "sousa", &bytes, |f| Options::new(f, W, H).media(media));
        let (mut top, mut bottom) = (0.0f64, 0.0f64);
        for y in 0..H {
            for x in 0..W {
                let s = shaft_radiance(cam.ray(x, y, W, H), to_sun.as_dvec3());
                let i = ((y * W + x) * 3) as usize;
                let amount = rgb[i + 1] as f64 / s[1];
                assert!(
                    amount <= bound * 1.01,
                    "{taps} taps: pixel ({x}, {y}): amount {amount} beyond {bound}"
                );
                for c in 0..3 {
                    // One amount for all channels: the blur is monochrome, the colour the light's.
                    assert!(
                        (rgb[i + c] as f64 / s[c] - amount).abs() <= 1e-3 * bound,
                        "{taps} taps: pixel ({x}, {y}) channel {c}"
                    );
                }
                if y < H / 2 - 2 {
                    top += amount / rows;
                } else if y >= H / 2 + 2 {
                    bottom += amount / rows;
                }
            }
        }
        eprintln!("sousa {taps} taps: mean amount top {top:.4}, bottom {bottom:.4}");
        assert!(bottom > 10.0 * top && bottom > 0.2, "{taps} taps: top {top}, bottom {bottom}");
        bottoms.push(bottom);
    }
    let ratio = bottoms[1] / bottoms[0];
    assert!((0.5..2.0).contains(&ratio), "3 taps {:.4} against 6 taps {:.4}", bottoms[1], bottoms[0]);
}

/// The sun behind the camera, shining along its view: the medium scatters its light back
/// towards the camera (the world-space `march` and `toth` show it), but the image-space
/// techniques have no screen position to blur towards and add nothing at all. Seed 002's known
/// failure, asserted rather than hidden.
#[test]
fn image_space_god_rays_miss_a_light_behind_the_camera() {
    let dir = gpu_test!();
    let behind = Vec3::new(0.0, 0.2, 1.0);
    let bytes = sky_over_wall(behind);
    let (none, _) = render(dir.path(), "none", &bytes, |f| Options::new(f, W, H));
    assert!(none.iter().all(|&v| v == 0.0), "black wall, black sky");
    for media in [
        Media::Mitchell(techniques::media::mitchell::Mitchell {
            samples: 60,
            resolution: ScreenFraction::Quarter,
            exposure: 1.921,
        }),
        Media::Sousa(techniques::media::sousa::Sousa {
            taps: 6,
            resolution: ScreenFraction::Quarter,
            brightness: 0.19,
        }),
    ] {
        let (rgb, _) = render(dir.path(), "image space", &bytes, |f| Options::new(f, W, H).media(media));
        assert!(rgb.iter().all(|&v| v == 0.0), "{media:?} shows light from behind the camera");
    }
    for media in [
        Media::March(techniques::media::march::March { steps: 16 }),
        Media::Toth(techniques::media::toth::Toth { samples: 16, block: 2, phase: Phase::Medium }),
    ] {
        let (rgb, _) = render(dir.path(), "world space", &bytes, |f| Options::new(f, W, H).media(media));
        let m = mean(&rgb);
        eprintln!("{media:?}: mean {m:?}");
        assert!(m.iter().all(|&c| c > 0.003), "{media:?} misses the back-scattered light: {m:?}");
    }
}

/// Mitchell with a point light: its emitter is a sphere of 0.02 × the scene's diagonal (the
/// wall's, 42.4 units: radius 0.849) around the light, drawn where a pixel's ray passes that
/// close in front of the surface. The occlusion image (full resolution) is computed here per
/// texel the same way, read bilinearly (clamped at the edges, 0 off screen), and each pixel's
/// radiance is (exposure / n) · (own sample + n samples towards the light) times the light's
/// irradiance at the camera, I/d², × albedo × HG: within 1.5 % of the full-exposure value.
#[test]
fn mitchells_blur_of_a_point_lights_sphere_matches_its_definition() {
    let dir = gpu_test!();
    let lamp = DVec3::new(0.0, 1.6, 4.0);
    let intensity = 3.0f64;
    let p = |x: f32, y: f32| Vec3::new(x, y, -20.0);
    let wall =
        [[p(-15.0, -15.0), p(15.0, -15.0), p(15.0, 15.0)], [p(-15.0, -15.0), p(15.0, 15.0), p(-15.0, 15.0)]];
    let mut scene = scene_of(&wall);
    scene.materials[0].gpu = lambert_material([0.0; 3]);
    scene.lights.push(light(LightKind::Point, lamp.as_vec3().to_array(), [0.0, -1.0, 0.0], intensity as f32));
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.media.push(FOG);
    scene.cameras.push(camera().file_camera());
    let bytes = compile(scene, kiln_compiler::settings::Settings { media_volume_res: 4, ..fast_settings() });
    let (samples, exposure) = (60u32, 1.921f32);
    let media = Media::Mitchell(techniques::media::mitchell::Mitchell {
        samples,
        resolution: ScreenFraction::Full,
        exposure,
    });
    let (rgb, _) = render(dir.path(), "mitchell point", &bytes, |f| Options::new(f, W, H).media(media));
    let cam = camera();
    let radius = 0.02 * (30.0f64 * 30.0 + 30.0 * 30.0).sqrt();
    let mask: Vec<f64> = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .map(|(x, y)| {
            let d = cam.ray(x, y, W, H);
            let t = (lamp - cam.eye).dot(d);
            let miss = (cam.eye + d * t - lamp).length();
            if t > 0.0 && miss <= radius { 1.0 } else { 0.0 }
        })
        .collect();
    assert!(mask.iter().sum::<f64>() >= 9.0, "the sphere covers a few pixels");
    let occlusion = |u: f64, v: f64| {
        if !(0.0..=1.0).contains(&u) || !(0.0..=1.0).contains(&v) {
            return 0.0;
        }
        let (fx, fy) = (u * W as f64 - 0.5, v * H as f64 - 0.5);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (wx, wy) = (fx - x0, fy - y0);
        let at = |x: f64, y: f64| {
            let (x, y) = (x.clamp(0.0, W as f64 - 1.0) as u32, y.clamp(0.0, H as f64 - 1.0) as u32);
            mask[(y * W + x) as usize]
        };
        (1.0 - wy) * ((1.0 - wx) * at(x0, y0) + wx * at(x0 + 1.0, y0))
            + wy * ((1.0 - wx) * at(x0, y0 + 1.0) + wx * at(x0 + 1.0, y0 + 1.0))
    };
    let (u_light, v_light) = cam.project_direction(lamp - cam.eye).expect("the lamp is in front");
    assert!(v_light < 0.45, "the lamp's image lies above the middle");
    let towards = (lamp - cam.eye).normalize();
    let irradiance = intensity / (lamp - cam.eye).length_squared();
    let Medium { sigma_a, sigma_s, g, .. } = FOG;
    let mut lit = 0;
    for y in 0..H {
        for x in 0..W {
            let (u, v) = ((x as f64 + 0.5) / W as f64, (y as f64 + 0.5) / H as f64);
            let n = samples as f64 * 1.4;
            let (su, sv) = ((u - u_light) / n, (v - v_light) / n);
            let sum = occlusion(u, v)
                + (1..=samples).map(|i| occlusion(u - i as f64 * su, v - i as f64 * sv)).sum::<f64>();
            let amount = exposure as f64 / samples as f64 * sum;
            let p = henyey_greenstein(g as f64, cam.ray(x, y, W, H).dot(towards));
            for c in 0..3 {
                let shaft = irradiance * sigma_s[c] as f64 / (sigma_a[c] + sigma_s[c]) as f64 * p;
                let got = rgb[((y * W + x) * 3) as usize + c] as f64;
                assert!(
                    (got - shaft * amount).abs() <= 0.015 * shaft * exposure as f64,
                    "pixel ({x}, {y}) channel {c}: {got:.6} vs {:.6} (amount {amount:.4})",
                    shaft * amount
                );
            }
            lit += (amount > 0.05) as u32;
        }
    }
    assert!(lit > 20, "{lit} pixels show shafts");
}
