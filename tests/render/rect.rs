//! A rect light over a diffuse floor, every pixel against the closed-form irradiance of a
//! uniformly emitting polygon: the direct pass, ray-traced shadows under an occluder (umbra,
//! fully lit floor and penumbra) and the reference path tracer.
//!
//! The irradiance at p (normal n) from a polygon of radiance L, corners aᵢ seen from p as unit
//! vectors, is E = L/2 · |Σᵢ angle(aᵢ, aᵢ₊₁) · n·normalize(aᵢ × aᵢ₊₁)| (Lambert's contour
//! integral; valid while the whole polygon is above p's horizon, as here), and the floor shows
//! albedo/π · E.

use std::time::Instant;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::{LightKind, Sky};
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{
    ALBEDO, H, Pinhole, TOLERANCE, W, albedo, compare_plane, fast_settings, floor_pixels, light, pixel_xy,
    ratio_stats, render, render_frames, square, srgb8,
};

/// The direct pass integrates a rect light with a 4 × 4 midpoint rule. Over the floor compared
/// here (at least 1.9 units from a 1 × 0.6 light) its error is below 0.3 % (computed against the
/// closed form over a 0.5-unit grid of the floor), added to the G-buffer's 1 %.
const DIRECT_TOLERANCE: f64 = TOLERANCE + 0.005;

/// The light: a 1 × 0.6 rectangle at height 2, tilted 22° towards +x, radiance 4 (also the
/// emissive quad of `emitters.rs`).
pub(crate) struct Rect {
    pub(crate) centre: DVec3,
    pub(crate) facing: DVec3,
    pub(crate) right: DVec3,
    pub(crate) up: DVec3,
    pub(crate) width: f64,
    pub(crate) height: f64,
    pub(crate) radiance: f64,
}

impl Rect {
    pub(crate) fn new() -> Rect {
        let facing = DVec3::new(0.4, -1.0, 0.0).normalize();
        let right = DVec3::Z;
        Rect {
            centre: DVec3::new(0.5, 2.0, -0.3),
            facing,
            right,
            up: facing.cross(right),
            width: 1.0,
            height: 0.6,
            radiance: 4.0,
        }
    }

    /// The same light as the player reads it (f32, as the file stores it).
    fn file_light(&self) -> kiln_format::manifest::Light {
        let mut l = light(
            LightKind::Rect { width: self.width as f32, height: self.height as f32 },
            self.centre.as_vec3().to_array(),
            self.facing.as_vec3().to_array(),
            self.radiance as f32,
        );
        l.right = self.right.as_vec3().to_array();
        l
    }

    /// The point at (s, t) ∈ [0, 1]² of the rectangle.
    pub(crate) fn at(&self, s: f64, t: f64) -> DVec3 {
        self.centre + self.right * ((s - 0.5) * self.width) + self.up * ((t - 0.5) * self.height)
    }

    /// Whether p sees the emitting side (with a margin: the closed form and the midpoint rule
    /// both hold there).
    pub(crate) fn in_front(&self, p: DVec3) -> bool {
        (p - self.centre).dot(self.facing) > 0.3
    }

    /// The closed-form irradiance at p on the floor (normal +y).
    pub(crate) fn irradiance(&self, p: DVec3) -> f64 {
        self.part_irradiance(p, 1.0)
    }

    /// The closed-form irradiance at p on the floor (normal +y) from the part s ∈ [0, s_max] of
    /// the rectangle (the polygon formula over that part's corners).
    pub(crate) fn part_irradiance(&self, p: DVec3, s_max: f64) -> f64 {
        let corners = [self.at(0.0, 0.0), self.at(s_max, 0.0), self.at(s_max, 1.0), self.at(0.0, 1.0)];
        let a = corners.map(|q| (q - p).normalize());
        let mut sum = 0.0;
        for i in 0..4 {
            let (u, v) = (a[i], a[(i + 1) % 4]);
            sum += u.dot(v).clamp(-1.0, 1.0).acos() * u.cross(v).normalize().y;
        }
        self.radiance / 2.0 * sum.abs()
    }

    /// Whether the ray o + t d (t > 0) crosses the rectangle grown by `margin` on every side
    /// (shrunk where negative), and if so whether from its emitting side (`Some(true)`).
    pub(crate) fn crossing(&self, o: DVec3, d: DVec3, margin: f64) -> Option<bool> {
        let denom = d.dot(self.facing);
        let t = (self.centre - o).dot(self.facing) / denom;
        let q = o + d * t - self.centre;
        (denom != 0.0
            && t > 0.0
            && q.dot(self.right).abs() <= 0.5 * self.width + margin
            && q.dot(self.up).abs() <= 0.5 * self.height + margin)
            .then_some(denom < 0.0)
    }

    /// Whether the ray o + t d (t > 0) crosses the rectangle, from either side, with a margin
    /// (the path tracer sees the light).
    fn crossed_by(&self, o: DVec3, d: DVec3) -> bool {
        self.crossing(o, d, 0.05).is_some()
    }
}

/// A floor of the analytic albedo lit by [`Rect`], plus `extra` triangles, seen by `cam`.
fn scene_bytes(cam: &Pinhole, extra: &[[Vec3; 3]]) -> Vec<u8> {
    let mut tris = square(0.0, 10.0).to_vec();
    tris.extend_from_slice(extra);
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = lambert_material(ALBEDO.map(srgb8));
    scene.lights.push(Rect::new().file_light());
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.cameras.push(cam.file_camera());
    compile(scene, fast_settings())
}

fn camera() -> Pinhole {
    Pinhole::new([2.0, 7.0, 6.0], [0.5, 0.0, -0.5], [0.0, 1.0, 0.0], 60.0, W, H)
}

#[test]
fn rect_light_on_a_diffuse_plane_matches_the_polygon_irradiance_in_the_direct_pass() {
    let dir = gpu_test!();
    let cam = camera();
    let rect = Rect::new();
    let bytes = scene_bytes(&cam, &[]);
    let a = albedo();
    let expected = |p: DVec3| a.map(|k| k / std::f64::consts::PI * rect.irradiance(p));
    // The light's integration alone, every pixel.
    let (rgb, _) = render(dir.path(), "rect-unshadowed", &bytes, |f| Options::new(f, W, H).unshadowed());
    let n = compare_plane(&rgb, &cam, 9.5, |p, _| rect.in_front(p), expected, DIRECT_TOLERANCE);
    assert!(n > (W * H / 2) as usize, "only {n} pixels compared");
    // With the cube shadow map (PCSS, 16 taps) on a floor nothing shadows. Known defect: a few
    // scattered pixels (19 of 4785 on lavapipe) lose exactly one tap of 16 to self-shadowing
    // (ratio 15/16); allowed here at up to 1 % of the pixels, nothing else.
    let (rgb, _) = render(dir.path(), "rect", &bytes, |f| Options::new(f, W, H));
    let mut acne = 0;
    for (i, p, _) in floor_pixels(&cam, 9.5) {
        if !rect.in_front(p) {
            continue;
        }
        let (x, y) = pixel_xy(i);
        let e = expected(p);
        for c in 0..3 {
            let ratio = rgb[i + c] as f64 / e[c];
            assert!(
                (ratio - 1.0).abs() <= DIRECT_TOLERANCE || (ratio - 15.0 / 16.0).abs() <= DIRECT_TOLERANCE,
                "pixel ({x}, {y}) channel {c}: {} vs analytic {} (ratio {ratio:.4})",
                rgb[i + c],
                e[c]
            );
        }
        acne += usize::from((rgb[i] as f64 / e[0] - 1.0).abs() > DIRECT_TOLERANCE);
    }
    eprintln!("shadow-mapped: {acne} of {n} pixels lose one PCSS tap");
    assert!(acne * 100 <= n, "{acne} of {n} pixels are self-shadowed");
}

/// An occluder: a 0.9 × 0.9 square at height 1 under the light, facing up.
const OCCLUDER: (f64, f64, f64, f64) = (0.7, -0.3, 1.0, 0.45);

/// The fraction of the light's area p sees past the occluder grown by `grow`, from a 48 × 48
/// grid of points on the light.
fn visible_fraction(rect: &Rect, p: DVec3, grow: f64) -> f64 {
    let (ox, oz, oy, half) = OCCLUDER;
    let s = half + grow;
    let k = 48;
    let mut seen = 0;
    for i in 0..k {
        for j in 0..k {
            let q = rect.at((i as f64 + 0.5) / k as f64, (j as f64 + 0.5) / k as f64);
            let x = p + (q - p) * ((oy - p.y) / (q.y - p.y));
            if (x.x - ox).abs() > s || (x.z - oz).abs() > s {
                seen += 1;
            }
        }
    }
    seen as f64 / (k * k) as f64
}

#[test]
fn rect_light_ray_traced_shadows_give_the_umbra_lit_floor_and_penumbra_the_geometry_implies() {
    let dir = gpu_test!();
    // Per pixel and frame one ray to a uniform point on the light decides the light's
    // visibility; the frames average to the visible fraction of its area, which scales the
    // direct pass's unshadowed radiance. Fully lit floor: the closed form; umbra: black;
    // penumbra: the closed form times the fraction computed here (on average over pixels).
    let cam = camera();
    let rect = Rect::new();
    let (ox, oz, oy, half) = OCCLUDER;
    let occluder =
        square(oy as f32, half as f32).map(|t| t.map(|v| v + Vec3::new(ox as f32, 0.0, oz as f32)));
    let bytes = scene_bytes(&cam, &occluder);
    let frames = 128;
    let (rgb, _) =
        render_frames(dir.path(), "rect-rt", &bytes, frames, |f| Options::new(f, W, H).rt_shadows(0.0, 0.0));
    // Pixels whose view of the floor the occluder hides are left out.
    let seen = |d: DVec3| {
        let q = cam.eye + d * ((oy - cam.eye.y) / d.y);
        (q.x - ox).abs() > half + 0.05 || (q.z - oz).abs() > half + 0.05
    };
    let a = albedo();
    let lit = |p: DVec3| a.map(|k| k / std::f64::consts::PI * rect.irradiance(p));
    let margin = 0.03;
    let fully_lit =
        |p: DVec3, d: DVec3| seen(d) && rect.in_front(p) && visible_fraction(&rect, p, margin) == 1.0;
    let n_lit = compare_plane(&rgb, &cam, 9.5, fully_lit, lit, DIRECT_TOLERANCE);
    let mut n_dark = 0;
    let mut penumbra = Vec::new();
    for (i, p, d) in floor_pixels(&cam, 9.5) {
        if !seen(d) || !rect.in_front(p) || visible_fraction(&rect, p, margin) == 1.0 {
            continue;
        }
        if visible_fraction(&rect, p, -margin) == 0.0 {
            let (x, y) = pixel_xy(i);
            for c in 0..3 {
                assert!(rgb[i + c] == 0.0, "pixel ({x}, {y}) at {p} is in the umbra: {}", rgb[i + c]);
            }
            n_dark += 1;
        } else if visible_fraction(&rect, p, 0.0) > 0.25 {
            penumbra.push((i, p, d));
        }
    }
    eprintln!("{n_lit} lit, {n_dark} umbra and {} penumbra pixels", penumbra.len());
    assert!(n_lit > 1000 && n_dark > 20 && penumbra.len() > 100, "the view does not test the shadow");
    // The penumbra by side of the occluder (a light sampled off-centre shifts one side's mean).
    // 128 binary samples per pixel: a relative spread of about √((1 − f)/(128 f)) ≤ 0.15 per
    // pixel, measured 0.03 to 0.07 on lavapipe, so about 1.5 % on the mean of the 8 or more pixels a side has.
    for side in 0..4 {
        let part: Vec<_> = penumbra
            .iter()
            .copied()
            .filter(|&(_, p, _)| usize::from(p.x > ox) + 2 * usize::from(p.z > oz) == side)
            .collect();
        let (mean, spread) = ratio_stats(&rgb, &part, |p, _| lit(p)[0] * visible_fraction(&rect, p, 0.0));
        eprintln!("penumbra side {side}: {} pixels, mean ratio {mean:.4} (spread {spread:.3})", part.len());
        assert!(part.len() >= 8, "penumbra side {side}: only {} pixels", part.len());
        assert!((mean - 1.0).abs() < 0.05, "penumbra side {side}: mean ratio {mean} to the visible fraction");
    }
}

#[test]
fn rect_light_reference_path_tracer_matches_the_polygon_irradiance() {
    let dir = gpu_test!();
    // Light sampling and BRDF sampling (which sees the rect light when it crosses it) under
    // MIS: unbiased, so the mean ratio to the closed form is 1 up to noise, in each third of
    // the floor by brightness. The albedo reaches the path tracer as stored (no sRGB target).
    let cam = camera();
    let rect = Rect::new();
    let file = dir.path().join("rect-reference.kiln");
    std::fs::write(&file, scene_bytes(&cam, &[])).unwrap();
    let o = Options::new(&file, W, H).unshadowed().reference().build();
    let (_, rgb) = kiln_player::reference::render(&o, 16, Instant::now()).expect("reference render");
    let a = albedo();
    let expected = |p: DVec3, _: DVec3| a[0] / std::f64::consts::PI * rect.irradiance(p);
    let mut pixels: Vec<_> = floor_pixels(&cam, 9.5)
        .into_iter()
        .filter(|&(_, p, d)| rect.in_front(p) && !rect.crossed_by(cam.eye, d))
        .collect();
    assert!(pixels.len() > (W * H / 2) as usize, "only {} pixels", pixels.len());
    pixels.sort_by(|x, y| expected(x.1, x.2).total_cmp(&expected(y.1, y.2)));
    for (k, third) in pixels.chunks(pixels.len().div_ceil(3)).enumerate() {
        let (mean, spread) = ratio_stats(&rgb, third, expected);
        eprintln!("brightness third {k}: {} pixels, mean ratio {mean:.4} (spread {spread:.3})", third.len());
        assert!((mean - 1.0).abs() < 0.02, "third {k}: mean ratio {mean} to the closed form");
    }
}

#[test]
fn the_camera_sees_the_rect_light_itself_in_the_frame_and_the_reference() {
    let dir = gpu_test!();
    // From below the light's emitting side shows its radiance, exactly, in the frame (the direct
    // pass intersects each pixel's ray with the rectangle) and in the path tracer (camera rays
    // count it with weight 1); from above (`camera()`) only its dark back would be seen, which is
    // what the other tests here rely on.
    let rect = Rect::new();
    let cam = Pinhole::new([0.5, 0.3, 1.5], [0.5, 2.0, -0.3], [0.0, 1.0, 0.0], 70.0, W, H);
    let bytes = scene_bytes(&cam, &[]);
    let (frame, _) = render(dir.path(), "rect-seen", &bytes, |f| Options::new(f, W, H).unshadowed());
    let file = dir.path().join("rect-seen.kiln");
    let o = Options::new(&file, W, H).reference().build();
    let (_, traced) = kiln_player::reference::render(&o, 4, Instant::now()).expect("reference render");
    // Whether every ray of the pixel's footprint crosses the light's emitting side (inside) or
    // none does (outside): the centre ray against the rectangle shrunk or grown by more than
    // half a footprint.
    let front =
        |x: u32, y: u32, margin: f64| rect.crossing(cam.eye, cam.ray(x, y, W, H), margin) == Some(true);
    let (mut inside, mut outside) = (0, 0);
    for y in 0..H {
        for x in 0..W {
            let i = (y * W + x) as usize * 3;
            if front(x, y, -0.08) {
                inside += 1;
                for (name, img) in [("frame", &frame), ("reference", &traced)] {
                    let v = &img[i..i + 3];
                    assert!(
                        v.iter().all(|&c| (c as f64 - rect.radiance).abs() < 1e-4),
                        "{name} ({x}, {y}): {v:?}"
                    );
                }
            } else if !front(x, y, 0.08) {
                outside += 1;
                assert!(
                    frame[i..i + 3].iter().all(|&c| (c as f64) < 0.5 * rect.radiance),
                    "frame ({x}, {y})"
                );
            }
        }
    }
    assert!(inside > 50 && outside > 50, "{inside} pixels inside the light, {outside} outside");
}
