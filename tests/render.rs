//! kiln-play on lavapipe: analytic direct-light checks pixel by pixel, the demo and PICA PICA
//! scenes with the validation layer on, and damaged or minimal files.
//!
//! Every test needs a Vulkan 1.3 device; without one they print why and pass, unless
//! `KILN_REQUIRE_VULKAN` is set (as `.ci/run` does), when they fail.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::{cornell_box, lambert_material};
use kiln_compiler::settings::Settings;
use kiln_format::manifest::{Camera, Light, LightKind, Sky};
use kiln_player::camera::CameraOverride;
use kiln_player::error::Exit;
use kiln_player::gpu::GpuOptions;
use kiln_player::headless::{self, HeadlessResult};
use kiln_player::image_out::read_exr;
use kiln_player::render::{GBufferMode, ReflectionRes, RenderSettings, RtSettings};
use kiln_player::session::SessionOptions;
use kiln_tests::{compile, scene_of, shared_scenes, vulkan};

fn options(
    file: &Path,
    width: u32,
    height: u32,
    camera: Option<CameraOverride>,
    shadows: bool,
) -> SessionOptions {
    SessionOptions {
        gpu: GpuOptions { validate: true, ..Default::default() },
        render: RenderSettings { shadow_maps: shadows, ..Default::default() },
        camera,
        ..SessionOptions::new(file, width, height)
    }
}

/// Options with the given ray-traced passes (no shadow maps).
fn rt_options(file: &Path, width: u32, height: u32, rt: RtSettings) -> SessionOptions {
    let mut o = options(file, width, height, None, false);
    o.render.rt = rt;
    o
}

/// Renders `bytes` headless to an EXR; returns the RGB radiance, asserting a clean run.
fn render(
    dir: &Path,
    name: &str,
    bytes: &[u8],
    opts: impl Fn(&Path) -> SessionOptions,
) -> (Vec<f32>, HeadlessResult) {
    render_frames(dir, name, bytes, 1, opts)
}

/// [`render`] writing the last of `frames` frames (the ray-traced passes average them).
fn render_frames(
    dir: &Path,
    name: &str,
    bytes: &[u8],
    frames: u32,
    opts: impl Fn(&Path) -> SessionOptions,
) -> (Vec<f32>, HeadlessResult) {
    let file = dir.join(format!("{name}.kiln"));
    std::fs::write(&file, bytes).unwrap();
    let exr = dir.join(format!("{name}.exr"));
    let o = opts(&file);
    let result =
        headless::run(&o, frames, Some(&exr), Instant::now()).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(result.session.validation_errors(), 0, "{name}: validation errors");
    // Close a second session on the same file, counting what the layer reports at teardown.
    let again = headless::run(&o, 1, None, Instant::now()).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(again.session.close(), 0, "{name}: validation errors at teardown (leaked objects?)");
    assert_eq!(result.non_finite, 0, "{name}: NaN or Inf in the frame");
    let (w, h, rgb) = read_exr(&exr).unwrap();
    assert_eq!((w, h), (o.width, o.height));
    assert!(rgb.iter().all(|v| v.is_finite()), "{name}: the EXR holds NaN or Inf");
    (rgb, result)
}

/// The linear value an 8-bit sRGB code decodes to (so that the G-buffer stores it exactly).
fn srgb8(code: u8) -> f32 {
    let c = code as f32 / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// A pinhole camera computed here, independently of the player: pixel (x, y), row 0 at the
/// top, looks through NDC (2(x+½)/W − 1, 1 − 2(y+½)/H).
struct Pinhole {
    eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    tan_half: f64,
    aspect: f64,
}

impl Pinhole {
    fn new(eye: [f64; 3], target: [f64; 3], up: [f64; 3], vfov_degrees: f64, w: u32, h: u32) -> Pinhole {
        let eye = DVec3::from_array(eye);
        let forward = (DVec3::from_array(target) - eye).normalize();
        let right = forward.cross(DVec3::from_array(up)).normalize();
        Pinhole {
            eye,
            forward,
            right,
            up: right.cross(forward),
            tan_half: (vfov_degrees.to_radians() * 0.5).tan(),
            aspect: w as f64 / h as f64,
        }
    }

    fn ray(&self, x: u32, y: u32, w: u32, h: u32) -> DVec3 {
        let nx = 2.0 * (x as f64 + 0.5) / w as f64 - 1.0;
        let ny = 1.0 - 2.0 * (y as f64 + 0.5) / h as f64;
        (self.forward + self.right * nx * self.tan_half * self.aspect + self.up * ny * self.tan_half)
            .normalize()
    }

    fn file_camera(&self) -> Camera {
        let t = self.eye + self.forward;
        Camera {
            name: "test".into(),
            position: self.eye.as_vec3().to_array(),
            target: t.as_vec3().to_array(),
            up: self.up.as_vec3().to_array(),
            vfov_degrees: (self.tan_half.atan() * 2.0).to_degrees() as f32,
            znear: 0.0,
            zfar: 0.0,
        }
    }
}

/// A square of half-size `s` in the plane y = `y`, facing up, as two triangles.
fn square(y: f32, s: f32) -> [[Vec3; 3]; 2] {
    let p = |x: f32, z: f32| Vec3::new(x, y, z);
    [[p(-s, -s), p(-s, s), p(s, s)], [p(-s, -s), p(s, s), p(s, -s)]]
}

fn light(kind: LightKind, position: [f32; 3], direction: [f32; 3], intensity: f32) -> Light {
    Light {
        name: "l".into(),
        kind,
        position,
        direction,
        right: [1.0, 0.0, 0.0],
        color: [1.0; 3],
        intensity,
        range: 0.0,
        casts_shadows: true,
    }
}

fn fast_settings() -> Settings {
    Settings { shaft_variants: Some(0), shadow_res: 512, ..Default::default() }
}

const ALBEDO: [u8; 3] = [188, 150, 120];
const W: u32 = 96;
const H: u32 = 72;

/// Compares every pixel whose camera ray meets the plane y = 0 inside |x|, |z| < `inside`
/// (and passes `keep`) with `expected(point)`; returns the pixels compared.
fn compare_plane(
    rgb: &[f32],
    cam: &Pinhole,
    inside: f64,
    keep: impl Fn(DVec3, DVec3) -> bool,
    expected: impl Fn(DVec3) -> [f64; 3],
    tolerance: f64,
) -> usize {
    let mut compared = 0;
    let mut worst = (0.0f64, 0u32, 0u32);
    for y in 0..H {
        for x in 0..W {
            let d = cam.ray(x, y, W, H);
            if d.y >= -1e-6 {
                continue;
            }
            let p = cam.eye + d * (-cam.eye.y / d.y);
            if p.x.abs() >= inside || p.z.abs() >= inside || !keep(p, d) {
                continue;
            }
            let e = expected(p);
            let i = ((y * W + x) * 3) as usize;
            for c in 0..3 {
                let got = rgb[i + c] as f64;
                let rel = (got - e[c]).abs() / e[c].max(1e-6);
                if rel > worst.0 {
                    worst = (rel, x, y);
                }
                assert!(
                    rel <= tolerance,
                    "pixel ({x}, {y}) channel {c}: {got} vs analytic {} ({:.3}% off)",
                    e[c],
                    rel * 100.0
                );
            }
            compared += 1;
        }
    }
    eprintln!(
        "{compared} pixels compared, worst relative error {:.4}% at ({}, {})",
        worst.0 * 100.0,
        worst.1,
        worst.2
    );
    compared
}

fn albedo() -> [f64; 3] {
    ALBEDO.map(|c| srgb8(c) as f64)
}

/// Relative tolerance of the analytic checks, 1 %. The albedo is an sRGB code, which the
/// G-buffer's RGBA8_SRGB target stores exactly on GPUs; lavapipe's sRGB conversion is
/// approximate (measured: −0.14 %, +0.11 %, +0.46 % on codes 188, 150, 120). The normal is 16-bit
/// octahedral (≤ 0.003°), the position rebuilt from 32-bit reversed depth.
const TOLERANCE: f64 = 0.01;

#[test]
fn point_light_on_a_diffuse_plane_matches_albedo_over_pi_times_i_cos_over_d2() {
    if !vulkan() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cam = Pinhole::new([0.0, 8.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 60.0, W, H);
    let mut scene = scene_of(&square(0.0, 10.0));
    scene.materials[0].gpu = lambert_material(ALBEDO.map(srgb8));
    let lp = [1.0f32, 3.0, -0.5];
    let intensity = 10.0;
    scene.lights.push(light(LightKind::Point, lp, [0.0, -1.0, 0.0], intensity));
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let a = albedo();
    let l = DVec3::from_array(lp.map(f64::from));
    // Both G-buffers: rasterised, and the visibility buffer resolved in compute.
    for mode in [GBufferMode::Raster, GBufferMode::Visibility] {
        let (rgb, _) = render(dir.path(), &format!("point-{mode:?}"), &bytes, |f| {
            let mut o = options(f, W, H, None, true);
            o.render.gbuffer = mode;
            o
        });
        let n = compare_plane(
            &rgb,
            &cam,
            9.5,
            |_, _| true,
            |p| {
                let to = l - p;
                let d2 = to.length_squared();
                let cos = to.y / d2.sqrt();
                a.map(|k| k / std::f64::consts::PI * intensity as f64 * cos / d2)
            },
            TOLERANCE,
        );
        assert!(n > (W * H / 2) as usize, "{mode:?}: only {n} pixels compared");
    }
}

#[test]
fn directional_light_on_a_diffuse_plane_is_albedo_over_pi_times_e_cos() {
    if !vulkan() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cam = Pinhole::new([3.0, 6.0, 5.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 50.0, W, H);
    let mut scene = scene_of(&square(0.0, 10.0));
    scene.materials[0].gpu = lambert_material(ALBEDO.map(srgb8));
    let travel = Vec3::new(-0.3, -1.0, 0.2).normalize();
    let irradiance = 3.0;
    scene.lights.push(light(LightKind::Directional, [0.0; 3], travel.to_array(), irradiance));
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let (rgb, _) = render(dir.path(), "directional", &bytes, |f| options(f, W, H, None, true));
    let a = albedo();
    let cos = -travel.y as f64;
    let n = compare_plane(
        &rgb,
        &cam,
        9.5,
        |_, _| true,
        |_| a.map(|k| k / std::f64::consts::PI * irradiance as f64 * cos),
        TOLERANCE,
    );
    assert!(n > (W * H / 3) as usize, "only {n} pixels compared");
}

#[test]
fn an_occluder_casts_the_shadow_its_geometry_implies() {
    if !vulkan() {
        return;
    }
    // Shadow maps: PCF blurs the edge over a few texels.
    occluder_case("occluder", 0.15, |f| options(f, W, H, None, true));
}

#[test]
fn ray_traced_hard_shadows_are_exact_up_to_the_pixel_at_the_umbra_edge() {
    if !vulkan() {
        return;
    }
    // A point light of radius 0: one ray per pixel decides exactly, so only pixels whose
    // footprint straddles the edge (about 0.06 units here) are left out.
    occluder_case("occluder-rt", 0.04, |f| {
        rt_options(f, W, H, RtSettings { shadows: true, ..RtSettings::OFF })
    });
}

fn occluder_case(name: &str, margin: f64, shadowed: impl Fn(&Path) -> SessionOptions) {
    let dir = tempfile::tempdir().unwrap();
    // A 2 × 2 square at height 1 under a point light at height 4: its umbra on the floor is the
    // square scaled by 4 / (4 − 1), |x|, |z| < 4/3.
    let cam = Pinhole::new([5.0, 9.0, 6.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 45.0, W, H);
    let mut tris: Vec<[Vec3; 3]> = square(0.0, 10.0).to_vec();
    tris.extend(square(1.0, 1.0));
    let mut scene = scene_of(&tris);
    scene.materials[0].gpu = lambert_material(ALBEDO.map(srgb8));
    let lp = [0.0f32, 4.0, 0.0];
    let intensity = 20.0;
    scene.lights.push(light(LightKind::Point, lp, [0.0, -1.0, 0.0], intensity));
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let (rgb, _) = render(dir.path(), name, &bytes, shadowed);
    let a = albedo();
    let l = DVec3::from_array(lp.map(f64::from));
    let edge = 4.0 / 3.0;
    // Pixels whose view of the floor the occluder hides are skipped.
    let visible = |p: DVec3, d: DVec3| {
        let t = (1.0 - cam.eye.y) / d.y;
        let q = cam.eye + d * t;
        let _ = p;
        !(q.x.abs() <= 1.05 && q.z.abs() <= 1.05)
    };
    let lit = |p: DVec3| {
        let to = l - p;
        let d2 = to.length_squared();
        a.map(|k| k / std::f64::consts::PI * intensity as f64 * (to.y / d2.sqrt()) / d2)
    };
    // Outside the umbra (beyond the PCF footprint) the floor is fully lit...
    let outside =
        |p: DVec3, d: DVec3| visible(p, d) && (p.x.abs() > edge + margin || p.z.abs() > edge + margin);
    let n_lit = compare_plane(&rgb, &cam, 6.0, outside, lit, TOLERANCE);
    // ...and inside it, black.
    let inside = |p: DVec3, d: DVec3| visible(p, d) && p.x.abs() < edge - margin && p.z.abs() < edge - margin;
    let mut n_dark = 0;
    for y in 0..H {
        for x in 0..W {
            let d = cam.ray(x, y, W, H);
            let p = cam.eye + d * (-cam.eye.y / d.y);
            if d.y < 0.0 && inside(p, d) {
                let i = ((y * W + x) * 3) as usize;
                let unshadowed = lit(p);
                for c in 0..3 {
                    assert!(
                        (rgb[i + c] as f64) < 1e-3 * unshadowed[c],
                        "pixel ({x}, {y}) at {p} should be in the umbra: {}",
                        rgb[i + c]
                    );
                }
                n_dark += 1;
            }
        }
    }
    eprintln!("{n_lit} lit and {n_dark} shadowed floor pixels checked");
    assert!(
        n_lit > 500 && n_dark > 30,
        "{n_lit} lit, {n_dark} shadowed pixels: the view does not test the shadow"
    );

    // With --shadows none the umbra is lit like the rest.
    let (unshadowed, _) = render(dir.path(), "occluder-none", &bytes, |f| options(f, W, H, None, false));
    let n = compare_plane(&unshadowed, &cam, 6.0, inside, lit, TOLERANCE);
    assert!(n == n_dark);
}

#[test]
fn demo_scene_renders_clean_in_png_and_exr_with_a_camera_override() {
    if !vulkan() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let bytes = compile(cornell_box(), fast_settings());
    let (rgb, result) = render(dir.path(), "demo", &bytes, |f| options(f, 64, 48, None, true));
    assert!(rgb.iter().any(|&v| v > 0.0), "the demo frame is black");
    assert!(result.session.times.first_frame_since_start_ms > 0.0);
    drop(result);
    // PNG through the same path, and a camera override that looks away from the box (sky only).
    let file = dir.path().join("demo.kiln");
    let png = dir.path().join("demo.png");
    headless::run(&options(&file, 64, 48, None, true), 2, Some(&png), Instant::now()).unwrap();
    let img = image::open(&png).unwrap().into_rgb8();
    assert_eq!(img.dimensions(), (64, 48));
    let away: CameraOverride = "0,1,3.9,0,1,100,40".parse().unwrap();
    let (sky, _) = render(dir.path(), "demo", &bytes, |f| options(f, 16, 16, Some(away), true));
    assert!(sky.iter().all(|&v| v == 0.0), "looking away from the box should see the black sky");
}

#[test]
fn pica_pica_renders_clean_with_three_lights_and_its_shadow_maps() {
    if !vulkan() {
        return;
    }
    let Some(scenes) = shared_scenes() else {
        eprintln!("skipping: ../shared/scenes is not here");
        return;
    };
    let mut inputs = Vec::new();
    let mut scene = kiln_compiler::import::import(&scenes.join("pica_pica/scene.gltf")).unwrap();
    let side = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/pica_pica.toml");
    kiln_compiler::import::sidecar::Sidecar::load(&side, &mut inputs)
        .unwrap()
        .apply(&mut scene, "pica_pica.toml")
        .unwrap();
    let bytes = compile(scene, Settings { shaft_variants: Some(0), shadow_res: 256, ..Default::default() });
    let dir = tempfile::tempdir().unwrap();
    let (rgb, result) = render(dir.path(), "pica", &bytes, |f| options(f, 160, 90, None, true));
    let s = &result.session;
    assert_eq!(s.scene.manifest.lights.len(), 3);
    assert_eq!(s.scene.shadow_maps.len(), 3, "every light's shadow map is resident");
    assert_eq!(s.scene.textures.len(), s.scene.manifest.textures.len());
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let lit = rgb.chunks_exact(3).filter(|p| p.iter().sum::<f32>() > 0.05).count();
    assert!(lit > rgb.len() / 3 / 4, "only {lit} pixels are lit");

    // The visibility buffer resolved in compute (trilinear filtering from the texel buffer's mip
    // chains, normal maps through ray differentials) gives the rasterised frame.
    let (vis, _) = render(dir.path(), "pica-vis", &bytes, |f| {
        let mut o = options(f, 160, 90, None, true);
        o.render.gbuffer = GBufferMode::Visibility;
        o
    });
    let close = rgb.iter().zip(&vis).filter(|(a, b)| (*a - *b).abs() <= 0.02 * a.abs().max(0.01)).count();
    eprintln!(
        "pica_pica: {:.2} % of channels within 2 % between raster and visibility G-buffers",
        100.0 * close as f64 / rgb.len() as f64
    );
    assert!(close as f64 >= 0.98 * rgb.len() as f64, "{close} of {} channels agree", rgb.len());

    // The hybrid pipeline: every ray-traced pass, both reflection resolutions and both
    // G-buffers, validation clean (render asserts it), finite, and close to the shadow-mapped
    // frame on average.
    for (res, gbuffer) in
        [(ReflectionRes::Full, GBufferMode::Raster), (ReflectionRes::Half, GBufferMode::Visibility)]
    {
        let rt = RtSettings {
            shadows: true,
            ao: true,
            reflections: Some(res),
            light_radius: 0.05,
            sun_degrees: 0.53,
            ..RtSettings::OFF
        };
        let (traced, result) = render_frames(dir.path(), "pica-rt", &bytes, 2, |f| {
            let mut o = rt_options(f, 160, 90, rt);
            o.render.gbuffer = gbuffer;
            o
        });
        assert!(result.session.warnings.is_empty(), "{:?}", result.session.warnings);
        let mean = |v: &[f32]| v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
        let (a, b) = (mean(&rgb), mean(&traced));
        eprintln!("pica_pica mean radiance: shadow maps {a:.4}, ray traced ({res:?}) {b:.4}");
        assert!((b / a - 1.0).abs() < 0.25, "{res:?}: mean radiance {b} vs {a} with shadow maps");
    }
}

#[test]
fn damaged_files_fail_cleanly_and_minimal_files_render() {
    if !vulkan() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let good = compile(cornell_box(), fast_settings());
    let file = kiln_format::read::KilnFile::from_bytes(&good, Default::default()).unwrap();
    let vert = file.find(kiln_format::sections::VERTICES, 0).unwrap().entry;
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("truncated", good[..good.len() / 2].to_vec()),
        ("flipped vertex byte", {
            let mut b = good.clone();
            b[vert.offset as usize + 5] ^= 0x40;
            b
        }),
        ("not a kiln file", b"glTF binary, not kiln".repeat(10)),
        ("empty", Vec::new()),
    ];
    for (name, bytes) in cases {
        let path = dir.path().join(format!("{}.kiln", name.replace(' ', "-")));
        std::fs::write(&path, &bytes).unwrap();
        let err = headless::run(
            &options(&path, 32, 32, None, true),
            1,
            Some(&dir.path().join("x.png")),
            Instant::now(),
        )
        .unwrap_err();
        assert_eq!(err.exit, Exit::BadInput, "{name}: {}", err.message);
        assert!(
            err.message.contains(path.to_str().unwrap()) || err.message.contains("invalid"),
            "{name}: {}",
            err.message
        );
    }
    let missing = dir.path().join("missing.kiln");
    let err = headless::run(&options(&missing, 32, 32, None, true), 1, None, Instant::now()).unwrap_err();
    assert_eq!(err.exit, Exit::Io, "{}", err.message);

    // No lights: no shadow maps, no BRDF table, no textures. It renders emission and sky only.
    let mut scene = scene_of(&square(0.0, 1.0));
    scene.materials[0].gpu = lambert_material([0.0; 3]);
    scene.materials[0].gpu.emission = [0.5, 0.25, 0.125];
    scene.sky = Sky { radiance: [0.1, 0.2, 0.3] };
    let bytes = compile(scene, fast_settings());
    let (rgb, result) = render(dir.path(), "minimal", &bytes, |f| {
        options(f, 32, 32, Some("0,3,0.01,0,0,0,90".parse().unwrap()), true)
    });
    assert!(result.session.scene.shadow_maps.is_empty() && result.session.scene.brdf_lut.is_none());
    assert!(rgb.chunks_exact(3).any(|p| p == [0.5, 0.25, 0.125]), "emission is written as is");
    assert!(rgb.chunks_exact(3).any(|p| p == [0.1, 0.2, 0.3]), "the sky is written as is");
    let skipped: Vec<_> =
        result.session.scene.sections.iter().filter(|s| !s.uploaded).map(|s| s.section.clone()).collect();
    assert!(skipped.iter().any(|s| s == "bvh"), "the BVH is not uploaded: no pass traces rays ({skipped:?})");
}

/// Floor pixels of `rgb` (plane y = 0 seen by `cam`, inside |x|, |z| < `inside`) with the
/// point they show.
fn floor_pixels(cam: &Pinhole, inside: f64) -> Vec<(usize, DVec3, DVec3)> {
    let mut out = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let d = cam.ray(x, y, W, H);
            if d.y >= -1e-6 {
                continue;
            }
            let p = cam.eye + d * (-cam.eye.y / d.y);
            if p.x.abs() < inside && p.z.abs() < inside {
                out.push((((y * W + x) * 3) as usize, p, d));
            }
        }
    }
    out
}

/// Mean over `pixels` of got / expected (one channel: the scenes are grey), and the spread
/// (standard deviation) of that ratio.
fn ratio_stats(
    rgb: &[f32],
    pixels: &[(usize, DVec3, DVec3)],
    expected: impl Fn(DVec3, DVec3) -> f64,
) -> (f64, f64) {
    let r: Vec<f64> = pixels.iter().map(|&(i, p, d)| rgb[i] as f64 / expected(p, d)).collect();
    let mean = r.iter().sum::<f64>() / r.len() as f64;
    let var = r.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / r.len() as f64;
    (mean, var.sqrt())
}

#[test]
fn ray_traced_ao_under_a_ceiling_matches_the_analytic_openness_and_converges() {
    if !vulkan() {
        return;
    }
    // A floor under a ceiling at height h, sky radiance S, AO radius R > h. With cosine-weighted
    // rays u = cos²θ is uniform; a ray hits the ceiling at t = h / cosθ, contributing (t/R)²
    // when t < R and 1 otherwise, so the openness is k (1 + ln(1/k)) with k = (h/R)², and a
    // diffuse floor shows albedo · S · openness.
    let dir = tempfile::tempdir().unwrap();
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
    let rt = RtSettings { ao: true, ao_radius: Some(r as f32), ..RtSettings::OFF };
    let (one, _) = render(dir.path(), "ao-1", &bytes, |f| rt_options(f, W, H, rt));
    let (many, _) = render_frames(dir.path(), "ao-32", &bytes, 32, |f| rt_options(f, W, H, rt));
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
    let (off, _) = render(dir.path(), "ao-off", &bytes, |f| options(f, W, H, None, false));
    let (m_off, _) = ratio_stats(&off, &pixels, |_, _| albedo as f64 * sky as f64);
    assert!((m_off - 1.0).abs() < 0.01, "without AO: {m_off}");
}

#[test]
fn ray_traced_reflections_of_a_mirror_floor_show_the_sky_and_an_emitter_at_the_fresnel_weight() {
    if !vulkan() {
        return;
    }
    // A smooth metal floor (F0 = base) under an emissive panel covering x in [−1, 1] at height
    // 2, facing down, in a sky of radiance S. A pixel's mirror ray sees the panel (radiance E)
    // or the sky; it shows F · L with Schlick's F at the view angle (α = 10⁻³: G2/G1 = 1 and
    // the lobe is a mirror to within a pixel). The split-sum fallback cannot see the panel.
    let dir = tempfile::tempdir().unwrap();
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
    let mut metal = lambert_material([base; 3]);
    metal.flags &= !kiln_format::sections::MaterialFlags::DIFFUSE_ONLY;
    metal.metallic = 1.0;
    metal.roughness = 0.0;
    scene.materials[0].gpu = metal;
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
    for res in [ReflectionRes::Full, ReflectionRes::Half] {
        let rt = RtSettings { reflections: Some(res), ..RtSettings::OFF };
        let name = format!("mirror-{res:?}");
        let (rgb, _) = render_frames(dir.path(), &name, &bytes, 4, |f| rt_options(f, W, H, rt));
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
        let (tolerance, reach) = if res == ReflectionRes::Full { (0.03, 0) } else { (0.03, 2) };
        let sees_at = |x: i64, y: i64| {
            let d = cam.ray(x.clamp(0, W as i64 - 1) as u32, y.clamp(0, H as i64 - 1) as u32, W, H);
            (d.y < -1e-6).then(|| sees(cam.eye + d * (-cam.eye.y / d.y), d)).flatten()
        };
        for &(i, p, d) in &pixels {
            let (x, y) = (((i / 3) as u32 % W) as i64, ((i / 3) as u32 / W) as i64);
            let here = sees_at(x, y);
            if (-reach..=reach).any(|dy| (-reach..=reach).any(|dx| sees_at(x + dx, y + dy) != here)) {
                continue;
            }
            let rel = (rgb[i] as f64 / expected(p, d) - 1.0).abs();
            assert!(rel < tolerance, "{res:?}: floor at {p}: {} vs {} ({rel})", rgb[i], expected(p, d));
        }
    }
    let (split, _) = render(dir.path(), "mirror-off", &bytes, |f| options(f, W, H, None, false));
    let on_panel: Vec<_> = pixels.iter().copied().filter(|&(_, p, d)| sees(p, d) == Some(true)).collect();
    let (m_split, _) = ratio_stats(&split, &on_panel, |_, d| fresnel(d) * sky as f64);
    assert!((m_split - 1.0).abs() < 0.03, "the split sum shows the sky everywhere: {m_split}");
}

#[test]
fn accumulation_restarts_when_the_camera_moves_or_the_size_changes() {
    if !vulkan() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("demo.kiln");
    std::fs::write(&file, compile(cornell_box(), fast_settings())).unwrap();
    let all = RtSettings {
        shadows: true,
        ao: true,
        reflections: Some(ReflectionRes::Half),
        light_radius: 0.05,
        ..RtSettings::OFF
    };
    let mut session =
        kiln_player::session::Session::open(&rt_options(&file, 64, 48, all), Instant::now()).unwrap();
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

#[test]
fn reference_path_tracer_reflects_a_uniform_sky_off_rough_metal_with_the_ggx_albedo() {
    if !vulkan() {
        return;
    }
    // A white-furnace check of the reference path tracer's GGX: a metal floor with F0 = 1 in a
    // sky of radiance 1 reflects exactly the directional albedo E(n·v, roughness) of
    // single-scattering GGX with height-correlated Smith (a half-space sees only the sky, so one
    // bounce is the whole answer). E comes from the compiler's independent quadrature of the
    // same BRDF (`brdf_lut::integrate`, checked against Gauss–Legendre at 1e-3), so the sampling
    // (visible normals), the evaluation and their MIS weights must agree for the mean to match.
    let dir = tempfile::tempdir().unwrap();
    let roughness = [0.2f32, 0.5, 1.0];
    let cam = Pinhole::new([0.0, 6.0, 9.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 60.0, W, H);
    let strip = |x0: f32, x1: f32| {
        let p = |x: f32, z: f32| Vec3::new(x, 0.0, z);
        [[p(x0, -20.0), p(x0, 20.0), p(x1, 20.0)], [p(x0, -20.0), p(x1, 20.0), p(x1, -20.0)]]
    };
    let bounds = [(-30.0f32, -1.0f32), (-1.0, 1.0), (1.0, 30.0)];
    let mut tris = Vec::new();
    for &(x0, x1) in &bounds {
        tris.extend(strip(x0, x1));
    }
    let mut scene = scene_of(&tris);
    scene.materials.clear();
    for (i, &r) in roughness.iter().enumerate() {
        let mut m = lambert_material([1.0; 3]);
        m.flags &= !kiln_format::sections::MaterialFlags::DIFFUSE_ONLY;
        m.metallic = 1.0;
        m.roughness = r;
        scene.materials.push(kiln_compiler::ir::Material { name: format!("metal {r}"), gpu: m });
        scene.triangle_materials[2 * i..2 * i + 2].fill(i as u32);
    }
    scene.sky = Sky { radiance: [1.0; 3] };
    scene.cameras.push(cam.file_camera());
    let file = dir.path().join("furnace.kiln");
    std::fs::write(&file, compile(scene, fast_settings())).unwrap();
    let mut o = options(&file, W, H, None, false);
    o.render.reference = true;
    let (_, rgb) = kiln_player::reference::render(&o, 64, Instant::now()).expect("reference render");
    for (k, &r) in roughness.iter().enumerate() {
        let (x0, x1) = bounds[k];
        // Pixels well inside the strip (the pixel footprint never crosses its edges).
        let pixels: Vec<_> = floor_pixels(&cam, 19.0)
            .into_iter()
            .filter(|&(_, p, _)| p.x > x0 as f64 + 0.2 && p.x < x1 as f64 - 0.2)
            .collect();
        let expected = |_: DVec3, d: DVec3| {
            let (rr, gg) = kiln_compiler::bake::brdf_lut::integrate(-d.normalize().y, r as f64, 4096);
            rr + gg
        };
        let (mean, spread) = ratio_stats(&rgb, &pixels, expected);
        eprintln!(
            "roughness {r}: {} pixels, mean ratio to E(n·v) {mean:.4} (spread {spread:.4})",
            pixels.len()
        );
        assert!(pixels.len() > 300, "roughness {r}: only {} pixels", pixels.len());
        assert!((mean - 1.0).abs() < 0.01, "roughness {r}: mean ratio {mean} to the GGX albedo");
    }
}
