//! What the rendering tests share: scenes compiled in memory and rendered headless with the
//! validation layer on, the options they render with, a pinhole camera computed independently of
//! the player, and the per-pixel comparisons against closed forms.

use std::path::Path;
use std::time::Instant;

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_compiler::ir::{Scene, Texture, TextureRole};
use kiln_compiler::settings::Settings;
use kiln_format::manifest::{Camera, Light, LightKind, Wrap};
use kiln_format::sections::{GpuMaterial, MaterialFlags};
use kiln_player::headless::{self, HeadlessResult};
use kiln_player::image_out::read_exr;
use kiln_tests::Options;

/// Ray-traced shadows, AO and half-resolution reflections.
pub fn traced(o: Options) -> Options {
    o.rt_shadows(0.05, 0.0).rt_ao(None).rt_reflections(kiln_tests::Reflections::Half)
}

/// A headless run's written EXR (its bytes), the session's load breakdown and whether it still
/// showed the fallback at the end.
pub struct WrittenExr {
    pub bytes: Vec<u8>,
    pub times: kiln_player::session::LoadTimes,
    pub behind: bool,
}

/// Renders `frames` frames of `o` headless to `dir/name.exr`, asserting finite radiance and no
/// validation errors.
pub fn written_exr(dir: &Path, name: &str, o: Options, frames: u32) -> WrittenExr {
    let out = dir.join(format!("{name}.exr"));
    let r = headless::run(&o.build(), frames, Some(&out), Instant::now())
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(r.non_finite, 0, "{name}: NaN or Inf in the frame");
    let (times, behind) = (r.session.times.clone(), r.session.showing_fallback());
    assert_eq!(r.session.close(), 0, "{name}: validation errors");
    WrittenExr { bytes: std::fs::read(out).unwrap(), times, behind }
}

/// Renders `bytes` headless to an EXR; returns the RGB radiance, asserting a clean run.
pub fn render(
    dir: &Path,
    name: &str,
    bytes: &[u8],
    opts: impl Fn(&Path) -> Options,
) -> (Vec<f32>, HeadlessResult) {
    render_frames(dir, name, bytes, 1, opts)
}

/// [`render`] writing the last of `frames` frames (the ray-traced passes average them).
pub fn render_frames(
    dir: &Path,
    name: &str,
    bytes: &[u8],
    frames: u32,
    opts: impl Fn(&Path) -> Options,
) -> (Vec<f32>, HeadlessResult) {
    let file = dir.join(format!("{name}.kiln"));
    std::fs::write(&file, bytes).unwrap();
    let exr = dir.join(format!("{name}.exr"));
    let o = opts(&file).build();
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
pub fn srgb8(code: u8) -> f32 {
    let c = code as f32 / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// A pinhole camera computed here, independently of the player: pixel (x, y), row 0 at the
/// top, looks through NDC (2(x+½)/W − 1, 1 − 2(y+½)/H).
pub struct Pinhole {
    pub eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    tan_half: f64,
    aspect: f64,
}

impl Pinhole {
    /// Looks from `eye` at `target`, `up` upwards, `vfov_degrees` tall, for a `w` × `h` image.
    pub fn new(eye: [f64; 3], target: [f64; 3], up: [f64; 3], vfov_degrees: f64, w: u32, h: u32) -> Pinhole {
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

    /// The direction through the centre of pixel (x, y) of a `w` × `h` image.
    pub fn ray(&self, x: u32, y: u32, w: u32, h: u32) -> DVec3 {
        let nx = 2.0 * (x as f64 + 0.5) / w as f64 - 1.0;
        let ny = 1.0 - 2.0 * (y as f64 + 0.5) / h as f64;
        (self.forward + self.right * nx * self.tan_half * self.aspect + self.up * ny * self.tan_half)
            .normalize()
    }

    /// Where the direction `w` (a point at infinity) lies in a `w` × `h` image's texture
    /// coordinates (x right, y down, the image [0, 1]²); `None` behind the camera.
    pub fn project_direction(&self, dir: DVec3) -> Option<(f64, f64)> {
        let depth = dir.dot(self.forward);
        if depth <= 0.0 {
            return None;
        }
        let nx = dir.dot(self.right) / depth / (self.tan_half * self.aspect);
        let ny = dir.dot(self.up) / depth / self.tan_half;
        Some((0.5 + 0.5 * nx, 0.5 - 0.5 * ny))
    }

    /// The same camera as a file's camera record.
    pub fn file_camera(&self) -> Camera {
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
pub fn square(y: f32, s: f32) -> [[Vec3; 3]; 2] {
    let p = |x: f32, z: f32| Vec3::new(x, y, z);
    [[p(-s, -s), p(-s, s), p(s, s)], [p(-s, -s), p(s, s), p(s, -s)]]
}

/// A `width` × `height` texture, repeating, bilinearly magnified, whose texel (x, y) is
/// `f(x / width, y / height)`.
pub fn texture(
    name: &str,
    width: u32,
    height: u32,
    role: TextureRole,
    f: impl Fn(f32, f32) -> [u8; 4],
) -> Texture {
    let rgba = (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .flat_map(|(x, y)| f(x as f32 / width as f32, y as f32 / height as f32))
        .collect();
    Texture {
        name: name.into(),
        width,
        height,
        rgba,
        role,
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        mag_linear: true,
    }
}

/// Texture coordinates over the floor [`square`]`(y, 10)`: `repeats` times across it in u and v.
pub fn square_uvs(scene: &mut Scene, repeats: f32) {
    scene.uvs = scene
        .vertices
        .iter()
        .map(|v| [(v.position[0] + 10.0) / 20.0 * repeats, (v.position[2] + 10.0) / 20.0 * repeats])
        .collect();
}

/// A white light that casts shadows (`direction`: where a directional light travels).
pub fn light(kind: LightKind, position: [f32; 3], direction: [f32; 3], intensity: f32) -> Light {
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

/// A metal: F0 = `base`, GGX of the given roughness.
pub fn metal(base: f32, roughness: f32) -> GpuMaterial {
    let mut m = lambert_material([base; 3]);
    m.flags &= !MaterialFlags::DIFFUSE_ONLY;
    m.metallic = 1.0;
    m.roughness = roughness;
    m
}

/// Compiler settings that keep the test scenes quick to bake: no shafts, 512² shadow maps, no
/// probes (`probes.rs` asks for its own).
pub fn fast_settings() -> Settings {
    Settings {
        shaft_variants: Some(0),
        shadow_res: 512,
        probes: kiln_compiler::settings::Probes::Off,
        ..Default::default()
    }
}

/// The analytic scenes' albedo, as sRGB codes.
pub const ALBEDO: [u8; 3] = [188, 150, 120];
/// The analytic scenes' image size.
pub const W: u32 = 96;
pub const H: u32 = 72;

/// Compares every pixel whose camera ray meets the plane y = 0 inside |x|, |z| < `inside`
/// (and passes `keep`) with `expected(point)`; returns the pixels compared.
pub fn compare_plane(
    rgb: &[f32],
    cam: &Pinhole,
    inside: f64,
    keep: impl Fn(DVec3, DVec3) -> bool,
    expected: impl Fn(DVec3) -> [f64; 3],
    tolerance: f64,
) -> usize {
    let mut compared = 0;
    let mut worst = (0.0f64, 0u32, 0u32);
    for (i, p, d) in floor_pixels(cam, inside) {
        if !keep(p, d) {
            continue;
        }
        let (x, y) = pixel_xy(i);
        let e = expected(p);
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
    eprintln!(
        "{compared} pixels compared, worst relative error {:.4}% at ({}, {})",
        worst.0 * 100.0,
        worst.1,
        worst.2
    );
    compared
}

/// [`ALBEDO`] decoded to linear.
pub fn albedo() -> [f64; 3] {
    ALBEDO.map(|c| srgb8(c) as f64)
}

/// Relative tolerance of the analytic checks, 1 %. The albedo is an sRGB code, which the
/// G-buffer's RGBA8_SRGB target stores exactly on GPUs; lavapipe's sRGB conversion is
/// approximate (measured: −0.14 %, +0.11 %, +0.46 % on codes 188, 150, 120). The normal is 16-bit
/// octahedral (≤ 0.003°), the position rebuilt from 32-bit reversed depth.
pub const TOLERANCE: f64 = 0.01;

/// Floor pixels of a `W` × `H` image (plane y = 0 seen by `cam`, inside |x|, |z| < `inside`):
/// the index of their red value, the point they show and their ray.
pub fn floor_pixels(cam: &Pinhole, inside: f64) -> Vec<(usize, DVec3, DVec3)> {
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

/// The pixel (x, y) of the red value at `i` in a `W` × `H` RGB image.
pub fn pixel_xy(i: usize) -> (u32, u32) {
    let pixel = (i / 3) as u32;
    (pixel % W, pixel / W)
}

/// Mean over `pixels` of got / expected (one channel: the scenes are grey), and the spread
/// (standard deviation) of that ratio.
pub fn ratio_stats(
    rgb: &[f32],
    pixels: &[(usize, DVec3, DVec3)],
    expected: impl Fn(DVec3, DVec3) -> f64,
) -> (f64, f64) {
    let r: Vec<f64> = pixels.iter().map(|&(i, p, d)| rgb[i] as f64 / expected(p, d)).collect();
    let mean = r.iter().sum::<f64>() / r.len() as f64;
    let var = r.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / r.len() as f64;
    (mean, var.sqrt())
}
