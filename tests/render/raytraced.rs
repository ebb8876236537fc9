//! The hybrid pipeline's ray-traced passes against closed forms: AO under a ceiling, mirror
//! reflections of a panel and the sky at both resolutions; a mirror seen in a mirror (the metal
//! bounce); no firefly where a rough reflection or a GI path catches a glossy highlight (bounded
//! by the regularised lobe's peak); and the frame average restarting.

use std::path::Path;
use std::time::Instant;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::{cornell_box, lambert_material};
use kiln_format::manifest::{Light, LightKind, Sky};
use kiln_format::sections::GpuMaterial;
use kiln_test_support::gpu_test;
use kiln_tests::{Options, Reflections, compile, scene_of};

use crate::harness::{
    H, Pinhole, W, fast_settings, floor_pixels, light, metal, pixel_xy, ratio_stats, render, render_frames,
    square, srgb8,
};

#[test]
fn ray_traced_ao_under_a_ceiling_matches_the_analytic_openness_and_converges() {
    let dir = gpu_test!();
    // A floor under a ceiling at height h, sky radiance S, AO radius R > h. With cosine-weighted
    // rays u = cos²θ is uniform; a ray hits the ceiling at t = h / cosθ, contributing (t/R)²
    // when t < R and 1 otherwise, so the openness is k (1 + ln(1/k)) with k = (h/R)², and a
    // diffuse floor shows albedo · S · openness.
    let (h, r, sky) = (1.0f64, 2.0f64, 2.0f32);
    // An albedo the sRGB G-buffer stores exactly.
    let albedo = srgb8(188);
    let cam = Pinhole::new([0.0, 0.9, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 90.0, W, H);
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 20.0).to_vec();
    // The ceiling faces down (its front towards the floor).
    tris.extend(square(h as f32, 20.0).map(|t| [t[0], t[2], t[1]]));
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = lambert_material([albedo; 3]);
    scene.sky = Sky { radiance: [sky; 3] };
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let k = (h / r) * (h / r);
    let openness = k * (1.0 + (1.0 / k).ln());
    let expected = |_: DVec3, _: DVec3| albedo as f64 * sky as f64 * openness;
    let pixels = floor_pixels(&cam, 19.0);
    let ao = |f: &Path| Options::new(f, W, H).unshadowed().rt_ao(Some(r as f32));
    let (one, _) = render(dir.path(), "ao-1", &bytes, ao);
    let (many, _) = render_frames(dir.path(), "ao-32", &bytes, 32, ao);
    let (m1, s1) = ratio_stats(&one, &pixels, expected);
    let (m32, s32) = ratio_stats(&many, &pixels, expected);
    eprintln!(
        "AO openness {openness:.4}: 1 frame mean ratio {m1:.4} (spread {s1:.3}), 32 frames {m32:.4} (spread {s32:.3}) over {} pixels",
        pixels.len()
    );
    assert!(pixels.len() > 2000);
    assert!((m32 - 1.0).abs() < 0.01, "32 frames: mean ratio {m32} to the analytic AO");
    assert!((m1 - 1.0).abs() < 0.02, "1 frame: mean ratio {m1} to the analytic AO");
    // Averaging 32 frames divides the noise by about √32 ≈ 5.7.
    assert!(s32 < s1 / 4.0, "accumulation did not reduce the noise: {s1} → {s32}");
    // Without AO the floor sees the whole sky.
    let (off, _) = render(dir.path(), "ao-off", &bytes, |f| Options::new(f, W, H).unshadowed());
    let (m_off, _) = ratio_stats(&off, &pixels, |_, _| albedo as f64 * sky as f64);
    assert!((m_off - 1.0).abs() < 0.01, "without AO: {m_off}");
}

#[test]
fn ray_traced_reflections_of_a_mirror_floor_show_the_sky_and_an_emitter_at_the_fresnel_weight() {
    let dir = gpu_test!();
    // A smooth metal floor (F0 = base) under an emissive panel covering x in [−1, 1] at height
    // 2, facing down, in a sky of radiance S. A pixel's mirror ray sees the panel (radiance E)
    // or the sky; it shows F · L with Schlick's F at the view angle (α = 10⁻³: G2/G1 = 1 and
    // the lobe is a mirror to within a pixel). The split-sum fallback cannot see the panel.
    let (sky, emitted, base) = (1.0f32, 4.0f32, 0.8f32);
    let cam = Pinhole::new([0.0, 1.0, 6.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 60.0, W, H);
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 20.0).to_vec();
    let panel = [
        Vec3::new(-1.0, 2.0, -8.0),
        Vec3::new(1.0, 2.0, -8.0),
        Vec3::new(1.0, 2.0, 8.0),
        Vec3::new(-1.0, 2.0, 8.0),
    ];
    tris.push([panel[0], panel[1], panel[2]]);
    tris.push([panel[0], panel[2], panel[3]]);
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = metal(base, 0.0);
    let mut light = lambert_material([0.0; 3]);
    light.emission = [emitted; 3];
    scene.materials.push(kiln_compiler::ir::Material { name: "panel".into(), gpu: light });
    let n = scene.triangle_materials.len();
    scene.triangle_materials[n - 2..].fill(1);
    scene.sky = Sky { radiance: [sky; 3] };
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    // Where the mirror ray goes, and Schlick's F for the view angle.
    let sees = |p: DVec3, d: DVec3| -> Option<bool> {
        let m = DVec3::new(d.x, -d.y, d.z);
        let q = p + m * ((2.0 - p.y) / m.y);
        let x = q.x.abs();
        if (x - 1.0).abs() < 0.08 || q.z.abs() > 7.5 {
            return None;
        }
        Some(x < 1.0)
    };
    let fresnel = |d: DVec3| {
        let c = -d.normalize().y;
        base as f64 + (1.0 - base as f64) * (1.0 - c).powi(5)
    };
    let pixels: Vec<_> =
        floor_pixels(&cam, 15.0).into_iter().filter(|&(_, p, d)| sees(p, d).is_some()).collect();
    let expected = |p: DVec3, d: DVec3| {
        let l = if sees(p, d) == Some(true) { emitted } else { sky } as f64;
        fresnel(d) * l
    };
    for res in [Reflections::Full, Reflections::Half] {
        let name = format!("mirror-{res:?}");
        let (rgb, _) = render_frames(dir.path(), &name, &bytes, 4, |f| {
            Options::new(f, W, H).unshadowed().rt_reflections(res)
        });
        let on_panel: Vec<_> = pixels.iter().copied().filter(|&(_, p, d)| sees(p, d) == Some(true)).collect();
        let (m_panel, _) = ratio_stats(&rgb, &on_panel, expected);
        let (m_all, spread) = ratio_stats(&rgb, &pixels, expected);
        eprintln!(
            "{res:?}: {} floor pixels ({} see the panel): mean ratio {m_all:.4} (spread {spread:.4}), panel {m_panel:.4}",
            pixels.len(),
            on_panel.len()
        );
        assert!(on_panel.len() > 100 && pixels.len() > on_panel.len() + 500);
        // The split-sum compensation from the baked table adds up to about a percent.
        assert!((m_all - 1.0).abs() < 0.02 && (m_panel - 1.0).abs() < 0.02, "{res:?}");
        // Half resolution blends up to a full-resolution pixel across the reflected panel's
        // edge (which is no edge of the floor): pixels within two of it are left out.
        let (tolerance, reach) = if res == Reflections::Full { (0.03, 0) } else { (0.03, 2) };
        let sees_at = |x: i64, y: i64| {
            let d = cam.ray(x.clamp(0, W as i64 - 1) as u32, y.clamp(0, H as i64 - 1) as u32, W, H);
            (d.y < -1e-6).then(|| sees(cam.eye + d * (-cam.eye.y / d.y), d)).flatten()
        };
        for &(i, p, d) in &pixels {
            let (x, y) = pixel_xy(i);
            let (x, y) = (x as i64, y as i64);
            let here = sees_at(x, y);
            if (-reach..=reach).any(|dy| (-reach..=reach).any(|dx| sees_at(x + dx, y + dy) != here)) {
                continue;
            }
            let rel = (rgb[i] as f64 / expected(p, d) - 1.0).abs();
            assert!(rel < tolerance, "{res:?}: floor at {p}: {} vs {} ({rel})", rgb[i], expected(p, d));
        }
    }
    let (split, _) = render(dir.path(), "mirror-off", &bytes, |f| Options::new(f, W, H).unshadowed());
    let on_panel: Vec<_> = pixels.iter().copied().filter(|&(_, p, d)| sees(p, d) == Some(true)).collect();
    let (m_split, _) = ratio_stats(&split, &on_panel, |_, d| fresnel(d) * sky as f64);
    assert!((m_split - 1.0).abs() < 0.03, "the split sum shows the sky everywhere: {m_split}");
}

/// The periscope of `a_mirror_seen_in_a_mirror_shows_what_the_second_mirror_reflects`: mirrors
/// A and B of smooth metal of F0 `base`, the panel above B of material `panel`, a black sky,
/// `lights`; the file's bytes.
fn periscope(cam: &Pinhole, base: f32, panel: GpuMaterial, lights: Vec<Light>) -> Vec<u8> {
    let quad = |c: Vec3, t1: Vec3, t2: Vec3| {
        let p = [c - t1 - t2, c + t1 - t2, c + t1 + t2, c - t1 + t2];
        [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
    };
    let r2 = std::f32::consts::FRAC_1_SQRT_2;
    let mut tris =
        quad(Vec3::new(0.0, 0.0, -3.0), Vec3::new(r2, 0.0, -r2), Vec3::new(0.0, 0.5, 0.0)).to_vec();
    tris.extend(quad(Vec3::new(3.0, 0.0, -3.0), Vec3::new(r2, r2, 0.0), Vec3::new(0.0, 0.0, 1.0)));
    // The panel, 4 × 4 around (3, 3, −3), wound to face down.
    let (x0, x1, z0, z1, y) = PANEL;
    let p = |x: f32, z: f32| Vec3::new(x, y, z);
    tris.push([p(x0, z0), p(x1, z0), p(x1, z1)]);
    tris.push([p(x0, z0), p(x1, z1), p(x0, z1)]);
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = metal(base, 0.0);
    scene.materials.push(kiln_compiler::ir::Material { name: "panel".into(), gpu: panel });
    let n = scene.triangle_materials.len();
    scene.triangle_materials[n - 2..].fill(1);
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.lights = lights;
    scene.cameras.push(cam.file_camera());
    compile(scene, fast_settings())
}

/// The periscope's panel: x0, x1, z0, z1 and its height.
const PANEL: (f32, f32, f32, f32, f32) = (1.0, 5.0, -5.0, -1.0, 3.0);

#[test]
fn a_mirror_seen_in_a_mirror_shows_what_the_second_mirror_reflects() {
    let dir = gpu_test!();
    // A periscope: the camera looks along −z at mirror A (normal (1, 0, 1)/√2, 3 units ahead),
    // which turns its rays towards +x onto mirror B (normal (−1, 1, 0)/√2), which turns them up
    // into a panel at y = 3; the sky is black. Both mirrors are smooth metal of F0 = `base`
    // (α = 10⁻³: G2/G1 = 1), so a pixel shows F(45°)² times the panel's radiance where the
    // doubly mirrored ray meets it, Schlick's F at 45° incidence on both. Twice: the panel
    // emitting E, and the panel of albedo ρ lit by five point lights below it (whose terms at
    // that second hit, ρ/π · I cos θ / d² each, are shadow-tested from the second hit). Read from the sky about B's mirror direction (a single bounce) the pixel is black.
    let (base, emitted, rho, intensity) = (0.8f32, 3.0f32, 0.7f32, 6.0f32);
    // Five lamps under the panel, off the mirrors' paths: the shadow pass traces the second
    // hit's rays to the first REFLECTION_SECOND_HIT_LIGHTS (4), the shading kernel the fifth's.
    let lamps = [(4.5, 2.0, -4.5), (1.5, 2.0, -1.5), (4.6, 2.1, -1.4), (1.4, 1.9, -4.6), (3.2, 2.2, -5.5)]
        .map(|(x, y, z)| DVec3::new(x, y, z));
    let cam = Pinhole::new([0.0, 0.0, 0.0], [0.0, 0.0, -3.0], [0.0, 1.0, 0.0], 10.0, W, H);
    // Each pixel's path by its own arithmetic: the point where a ray meets a mirror's plane and
    // whether it lies inside it (with a margin), then the mirrored direction.
    let bounce = |o: DVec3, d: DVec3, centre: DVec3, n: DVec3, half: (f64, f64), t1: DVec3| {
        let t = (centre - o).dot(n) / d.dot(n);
        let q = o + d * t;
        let (u, v) = ((q - centre).dot(t1), (q - centre).dot(n.cross(t1)));
        (t > 0.0 && u.abs() < half.0 - 0.05 && v.abs() < half.1 - 0.05).then(|| (q, d - n * (2.0 * d.dot(n))))
    };
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let (na, nb) = (DVec3::new(s, 0.0, s), DVec3::new(-s, s, 0.0));
    let schlick = |c: f64| base as f64 + (1.0 - base as f64) * (1.0 - c).powi(5);
    let (x0, x1, z0, z1, y) = PANEL;
    // (pixel, F_A F_B, the panel point)
    let mut pixels = Vec::new();
    for yy in 0..H {
        for xx in 0..W {
            let d = cam.ray(xx, yy, W, H);
            let Some((qa, da)) =
                bounce(cam.eye, d, DVec3::new(0.0, 0.0, -3.0), na, (1.0, 0.5), DVec3::new(s, 0.0, -s))
            else {
                continue;
            };
            let Some((qb, db)) =
                bounce(qa, da, DVec3::new(3.0, 0.0, -3.0), nb, (1.0, 1.0), DVec3::new(s, s, 0.0))
            else {
                continue;
            };
            let at = qb + db * ((y as f64 - qb.y) / db.y);
            let inside = |v: f64, lo: f32, hi: f32| v > lo as f64 + 0.05 && v < hi as f64 - 0.05;
            if db.y > 0.0 && inside(at.x, x0, x1) && inside(at.z, z0, z1) {
                pixels.push((3 * (yy * W + xx) as usize, schlick(-d.dot(na)) * schlick(-da.dot(nb)), at));
            }
        }
    }
    assert!(
        pixels.len() > (W * H) as usize / 2,
        "{} pixels see the panel through both mirrors",
        pixels.len()
    );
    let mut glow = lambert_material([0.0; 3]);
    glow.emission = [emitted; 3];
    let lit: Vec<Light> = lamps
        .iter()
        .map(|l| light(LightKind::Point, l.as_vec3().to_array(), [0.0, -1.0, 0.0], intensity))
        .collect();
    let cases = [
        (
            "emissive",
            periscope(&cam, base, glow, vec![]),
            Box::new(|_: DVec3| emitted as f64) as Box<dyn Fn(DVec3) -> f64>,
        ),
        (
            "lit",
            periscope(&cam, base, lambert_material([rho; 3]), lit),
            Box::new(|q: DVec3| {
                let irradiance: f64 = lamps
                    .iter()
                    .map(|&lamp| {
                        let d2 = (lamp - q).length_squared();
                        intensity as f64 * ((q.y - lamp.y) / d2.sqrt()) / d2
                    })
                    .sum();
                rho as f64 / std::f64::consts::PI * irradiance
            }),
        ),
    ];
    for (name, bytes, radiance) in &cases {
        let (rgb, _) = render_frames(dir.path(), name, bytes, 2, |f| {
            Options::new(f, W, H).rt_reflections(Reflections::Full)
        });
        // The image against F² L, and each 8 × 8 block of it: a pixel alone moves by a few
        // percent where the lit panel's light falls off, the lobe (α = 10⁻³) landing its rays a
        // pixel's footprint apart there.
        let mut blocks = std::collections::BTreeMap::new();
        for &(i, f, q) in &pixels {
            let (x, y) = pixel_xy(i);
            let b: &mut (f64, f64) = blocks.entry((x / 8, y / 8)).or_default();
            *b = (b.0 + rgb[i] as f64, b.1 + f * radiance(q));
        }
        let (got, want) = blocks.values().fold((0.0, 0.0), |(g, w), b| (g + b.0, w + b.1));
        let mean = got / want;
        let worst = blocks.values().fold(0.0f64, |w, b| w.max((b.0 / b.1 - 1.0).abs()));
        eprintln!(
            "{name}: {} pixels through both mirrors: ratio {mean:.4}, worst block {worst:.4}",
            pixels.len()
        );
        assert!((mean - 1.0).abs() < 0.01, "{name}: the mirrors show {mean} times F² L");
        assert!(worst < 0.03, "{name}: a block through both mirrors is off by {worst}");
        // Without the metal bounce B's lobe reads the black sky.
        let (one, _) = render_frames(dir.path(), &format!("{name}-one"), bytes, 1, |f| {
            Options::new(f, W, H).rt_reflections(Reflections::Full).metal_bounce(0.0)
        });
        let dark = pixels.iter().map(|&(i, _, _)| one[i] as f64).fold(0.0f64, f64::max);
        assert!(dark < 1e-3, "{name}: with --reflection-metal-bounce 0 mirror B shows the sky, not {dark}");
    }
}

/// The glossy-wall scene: a floor (y = 0, |x|, |z| ≤ 2) of material `floor` in front of a
/// glossy metal wall (roughness 0.15, F0 1) at z = −2, a point light of intensity `intensity`
/// one unit in front of the wall, no sky; the camera looking at the floor and the wall.
fn glossy_wall(floor: kiln_format::sections::GpuMaterial, intensity: f32) -> (Pinhole, Vec<u8>) {
    let cam = Pinhole::new([0.0, 1.2, 3.5], [0.0, 0.3, -1.0], [0.0, 1.0, 0.0], 60.0, W, H);
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 2.0).to_vec();
    let wall = |x: f32, y: f32| Vec3::new(x, y, -2.0);
    tris.push([wall(-2.0, 0.0), wall(2.0, 0.0), wall(2.0, 2.0)]);
    tris.push([wall(-2.0, 0.0), wall(2.0, 2.0), wall(-2.0, 2.0)]);
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = floor;
    scene.materials.push(kiln_compiler::ir::Material { name: "wall".into(), gpu: metal(1.0, 0.15) });
    let n = scene.triangle_materials.len();
    scene.triangle_materials[n - 2..].fill(1);
    scene.lights.push(light(LightKind::Point, [0.0, 1.0, -1.0], [0.0, -1.0, 0.0], intensity));
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.cameras.push(cam.file_camera());
    (cam, compile(scene, fast_settings()))
}

/// The highest radiance a wall of roughness at least `roughness` (metal, F0 1) sends towards
/// floor points at z ≥ −1 under the glossy-wall light of `intensity`: F (≤ 1) × D_max · vis ·
/// cos (≤ D_max / (4 n·v), D_max = 1/(π r⁴)) × I / d² (d ≥ 1), with n·v ≥ 1/√21 from the
/// geometry alone.
fn wall_peak(roughness: f64, intensity: f32) -> f64 {
    1.0 / (std::f64::consts::PI * roughness.powi(4)) / (4.0 / 21f64.sqrt()) * intensity as f64
}

/// The floor pixels at z ≥ −1 and what `with` adds to each over `without`.
fn floor_added(cam: &Pinhole, with: &[f32], without: &[f32]) -> (usize, f64, f64) {
    let pixels: Vec<_> = floor_pixels(cam, 1.9).into_iter().filter(|&(_, p, _)| p.z >= -1.0).collect();
    let added: Vec<f64> = pixels.iter().map(|&(i, _, _)| (with[i] - without[i]) as f64).collect();
    let max = added.iter().cloned().fold(0.0, f64::max);
    (pixels.len(), added.iter().sum::<f64>() / added.len() as f64, max)
}

#[test]
fn a_rough_reflection_of_a_glossy_highlight_stays_below_the_regularised_lobes_peak() {
    let dir = gpu_test!();
    // A rough metal floor (roughness 0.5) before the glossy wall. Each floor pixel's one
    // reflection ray lands anywhere in its wide lobe; the few that meet the wall where it
    // mirrors the light would, unregularised, carry its highlight's peak D = 1/(π 0.15⁴) = 629:
    // fireflies hundreds of times the pixel's mean. With the hit's lobe widened to the floor's
    // roughness, a ray brings back at most the peak of a wall of roughness 0.5 (F·G2/G1 ≤ 1).
    let intensity = 4.0;
    let (cam, bytes) = glossy_wall(metal(0.9, 0.5), intensity);
    // The reflections alone: the frame with them less the frame without (no sky, no GI: the
    // split-sum fallback adds nothing).
    let (with, _) = render(dir.path(), "glossy-rt", &bytes, |f| {
        Options::new(f, W, H).unshadowed().rt_reflections(Reflections::Full)
    });
    let (without, _) = render(dir.path(), "glossy-off", &bytes, |f| Options::new(f, W, H).unshadowed());
    let peak = wall_peak(0.5, intensity);
    let (n, mean, max) = floor_added(&cam, &with, &without);
    eprintln!("{n} floor pixels: reflected mean {mean:.4}, max {max:.3}, bound {peak:.3}");
    assert!(n > 2000, "{n} floor pixels");
    // The wall's highlight is there (the reflections see it) and no sample exceeds the bound.
    assert!(mean > 0.05, "the floor reflects nothing of the wall's highlight: {mean}");
    assert!(max <= peak * 1.02, "a firefly: {max} above the regularised lobe's peak {peak}");
}

#[test]
fn path_traced_gi_off_a_glossy_highlight_stays_below_the_regularised_lobes_peak() {
    let dir = gpu_test!();
    // A Lambertian floor of albedo ρ before the glossy wall: each floor pixel's one GI path
    // leaves along a cosine lobe and the few that meet the wall where it mirrors the light
    // would bring back its highlight's peak. With the hits' roughness at least the default
    // --gi-regularize (0.5), one sample adds at most ρ × the peak of a wall of roughness 0.5.
    let (intensity, rho) = (4.0, 0.8f32);
    let (cam, bytes) = glossy_wall(lambert_material([rho; 3]), intensity);
    let (with, _) = render(dir.path(), "glossy-gi", &bytes, |f| Options::new(f, W, H).unshadowed().rt_gi(1));
    let (without, _) = render(dir.path(), "glossy-no-gi", &bytes, |f| Options::new(f, W, H).unshadowed());
    let peak = rho as f64 * wall_peak(0.5, intensity);
    let (n, mean, max) = floor_added(&cam, &with, &without);
    eprintln!("{n} floor pixels: GI mean {mean:.4}, max {max:.3}, bound {peak:.3}");
    assert!(n > 2000, "{n} floor pixels");
    assert!(mean > 0.01, "the floor receives nothing off the wall: {mean}");
    assert!(max <= peak * 1.02, "a firefly: {max} above the regularised lobe's peak {peak}");
}

#[test]
fn accumulation_restarts_when_the_camera_moves_or_the_size_changes() {
    let dir = gpu_test!();
    let file = dir.path().join("demo.kiln");
    std::fs::write(&file, compile(cornell_box(), fast_settings())).unwrap();
    let all = Options::new(&file, 64, 48).rt_shadows(0.05, 0.0).rt_ao(None).rt_reflections(Reflections::Half);
    let mut session = kiln_player::session::Session::open(&all.build(), Instant::now()).unwrap();
    for _ in 0..3 {
        session.frame(false).unwrap();
    }
    assert_eq!(session.renderer.accumulated(), 3);
    session.camera.turn(0.1, 0.0);
    session.frame(false).unwrap();
    assert_eq!(session.renderer.accumulated(), 1, "a camera move restarts the average");
    session.frame(false).unwrap();
    assert_eq!(session.renderer.accumulated(), 2);
    session.resize(40, 30).unwrap();
    session.frame(false).unwrap();
    assert_eq!(session.renderer.accumulated(), 1, "a resize restarts the average");
    assert_eq!(session.close(), 0, "validation errors");
}
