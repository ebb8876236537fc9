//! glTF `KHR_materials_ior` and `KHR_materials_specular` from the file to the pixel: a black,
//! nearly mirror-smooth floor (written here as glTF, imported by the compiler) under a uniform
//! sky of radiance 1 reflects, towards a camera at angle θ from its normal, exactly Schlick's
//! F0 + (F90 − F0)(1 − cos θ)⁵ (its diffuse part is black, the sky fills the mirror direction),
//! with the Khronos specification's F0 = min(((ior − 1)/(ior + 1))² · specularColorFactor, 1) ·
//! specularFactor and F90 = specularFactor, computed here.
//!
//! - The reference path tracer keeps F0's colour: each channel within 3 %.
//! - The raster frame (the direct pass's split sum) carries F0 through the 8-bit G-buffer as its
//!   luminance: within 6 % of the closed form with that grey F0 (the split-sum table's
//!   interpolation and the encoding's steps).
//!
//! At 30° from the normal F0 decides; at 75° F90 does. And a file whose material words say
//! something else than FORMAT.md allows (a half above 1; words without the flag) is refused.
//!
//! `KHR_materials_clearcoat` the same way: a grey Lambertian floor (its own specular lobe turned
//! off by specularFactor 0) under a smooth coat reflects, under the uniform sky,
//! 0.5 (1 − Fc) + Fc · E with Fc = 0.04 + 0.96 (1 − cos θ)⁵ and E ≈ 1 the smooth coat's lobe
//! albedo: the reference and the raster frame (the coat through the G-buffer's emission alpha)
//! each within 2 % (measured: 0.1 % and 0.6 %). A file with a coat outside [0, 1] is refused.

use std::time::Instant;

use glam::DVec3;
use kiln_format::manifest::Camera;
use kiln_player::reference::{Sampling, render_with};
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile};

use crate::harness::{fast_settings, render};

const W: u32 = 16;
const H: u32 = 12;
const IOR: f64 = 2.0;
const FACTOR: f64 = 0.8;
const COLOR: [f64; 3] = [1.0, 0.5, 0.25];

/// The floor's buffer: a 200-unit square at y = 0, facing up (positions, then indices).
fn floor_bin() -> Vec<u8> {
    let positions: [f32; 12] =
        [-100.0, 0.0, 100.0, 100.0, 0.0, 100.0, 100.0, 0.0, -100.0, -100.0, 0.0, -100.0];
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let mut bytes: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    bytes.extend(indices.iter().flat_map(|v| v.to_le_bytes()));
    bytes
}

/// The floor's glTF with `material` (a glTF material object) and `extensions` used.
fn floor_gltf_with(extensions: &str, material: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},
  "extensionsUsed":[{extensions}],
  "scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
  "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"material":0}}]}}],
  "materials":[{material}],
  "buffers":[{{"byteLength":60,"uri":"floor.bin"}}],
  "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":12}}],
  "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-100,0,-100],"max":[100,0,100]}},
    {{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#
    )
}

/// The floor's glTF: black, roughness 0.05, the extensions' ior and specular.
fn floor_gltf() -> String {
    floor_gltf_with(
        r#""KHR_materials_ior","KHR_materials_specular""#,
        &format!(
            r#"{{"pbrMetallicRoughness":{{"baseColorFactor":[0,0,0,1],"metallicFactor":0,"roughnessFactor":0.05}},
    "extensions":{{"KHR_materials_ior":{{"ior":{IOR}}},
      "KHR_materials_specular":{{"specularFactor":{FACTOR},"specularColorFactor":[{},{},{}]}}}}}}"#,
            COLOR[0], COLOR[1], COLOR[2]
        ),
    )
}

/// Schlick's reflectance at cosine `c`, per channel, for the extensions' F0 and F90.
fn schlick(c: f64) -> [f64; 3] {
    let r = ((IOR - 1.0) / (IOR + 1.0)).powi(2);
    COLOR.map(|k| {
        let f0 = (r * k).min(1.0) * FACTOR;
        f0 + (FACTOR - f0) * (1.0 - c).powi(5)
    })
}

/// The same with F0's luminance in place of its colour (what the raster G-buffer carries).
fn schlick_grey(c: f64) -> f64 {
    let r = ((IOR - 1.0) / (IOR + 1.0)).powi(2);
    let f0 = COLOR.map(|k| (r * k).min(1.0) * FACTOR);
    let grey = 0.2126 * f0[0] + 0.7152 * f0[1] + 0.0722 * f0[2];
    grey + (FACTOR - grey) * (1.0 - c).powi(5)
}

/// A camera 10 units from the floor's middle at `degrees` from its normal, seeing 1°.
fn camera(degrees: f64) -> Camera {
    let t = degrees.to_radians();
    let p = DVec3::new(0.0, t.cos(), t.sin()) * 10.0;
    Camera {
        name: "view".into(),
        position: p.as_vec3().to_array(),
        target: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        vfov_degrees: 1.0,
        znear: 0.1,
        zfar: 100.0,
    }
}

/// Asserts that each channel of `got` lies within `tolerance` (relative) of `want`'s.
fn assert_within(what: &str, got: [f64; 3], want: [f64; 3], tolerance: f64) {
    for ch in 0..3 {
        assert!(
            (got[ch] - want[ch]).abs() <= tolerance * want[ch],
            "{what}: channel {ch} {} against the closed form's {}",
            got[ch],
            want[ch]
        );
    }
}

/// Mean of each channel.
fn mean(rgb: &[f32]) -> [f64; 3] {
    let n = (rgb.len() / 3) as f64;
    [0, 1, 2].map(|c| rgb.iter().skip(c).step_by(3).map(|&v| f64::from(v)).sum::<f64>() / n)
}

/// The mean RGB of the floor in `gltf` under a uniform sky of radiance 1, seen at `degrees`
/// from its normal: (the reference path tracer's at 32 spp, the raster frame's).
fn reference_and_raster(
    dir: &std::path::Path,
    gltf: &std::path::Path,
    name: &str,
    degrees: f64,
) -> ([f64; 3], [f64; 3]) {
    let mut scene = kiln_compiler::import::import(gltf).expect("the floor imports");
    scene.sky.radiance = [1.0; 3];
    scene.cameras = vec![camera(degrees)];
    let bytes = compile(scene, fast_settings());
    let (raster, _) = render(dir, name, &bytes, |f| Options::new(f, W, H));
    let file = dir.join(format!("{name}.kiln"));
    let sampling = Sampling { spp: 32, seed: 1, bounces: 4, progress: false };
    let o = Options::new(&file, W, H).reference().build();
    let reference = mean(&render_with(&o, sampling, Instant::now()).expect("reference render").1);
    (reference, mean(&raster))
}

#[test]
fn ior_and_specular_set_the_dielectric_fresnel_in_the_reference_and_the_raster_frame() {
    let dir = gpu_test!();
    let gltf = dir.path().join("floor.gltf");
    std::fs::write(&gltf, floor_gltf()).unwrap();
    std::fs::write(dir.path().join("floor.bin"), floor_bin()).unwrap();
    for degrees in [30.0, 75.0] {
        let (reference, raster) =
            reference_and_raster(dir.path(), &gltf, &format!("floor{degrees}"), degrees);
        let c = degrees.to_radians().cos();
        let want = schlick(c);
        let grey = schlick_grey(c);
        eprintln!(
            "{degrees}°: reference {reference:?}, raster {raster:?}, closed form {want:?} (grey {grey:.4})"
        );
        assert_within(&format!("{degrees}°: the reference"), reference, want, 0.03);
        assert_within(&format!("{degrees}°: the raster frame (grey F0)"), raster, [grey; 3], 0.06);
    }
}

/// The coated floor's glTF: grey Lambertian base (no specular lobe), a smooth full clear coat.
fn coated_floor_gltf() -> String {
    floor_gltf_with(
        r#""KHR_materials_specular","KHR_materials_clearcoat""#,
        r#"{"pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1],"metallicFactor":0,"roughnessFactor":1},
    "extensions":{"KHR_materials_specular":{"specularFactor":0},
      "KHR_materials_clearcoat":{"clearcoatFactor":1,"clearcoatRoughnessFactor":0.05}}}"#,
    )
}

#[test]
fn a_clear_coat_reflects_its_fresnel_over_the_base_in_the_reference_and_the_raster_frame() {
    let dir = gpu_test!();
    let gltf = dir.path().join("coated.gltf");
    std::fs::write(&gltf, coated_floor_gltf()).unwrap();
    std::fs::write(dir.path().join("floor.bin"), floor_bin()).unwrap();
    for degrees in [30.0, 75.0] {
        let (reference, raster) =
            reference_and_raster(dir.path(), &gltf, &format!("coated{degrees}"), degrees);
        let fc = 0.04 + 0.96 * (1.0 - degrees.to_radians().cos()).powi(5);
        let want = 0.5 * (1.0 - fc) + fc;
        eprintln!("coat {degrees}°: reference {reference:?}, raster {raster:?}, closed form {want:.4}");
        assert_within(&format!("coat {degrees}°: the reference"), reference, [want; 3], 0.02);
        assert_within(&format!("coat {degrees}°: the raster frame"), raster, [want; 3], 0.02);
    }
    // A coat of 2 (offset 80 of the 96-byte record) is refused.
    use kiln_format::{Checksums, KilnFile, SceneView, sections};
    let good = std::fs::read(dir.path().join("coated30.kiln")).unwrap();
    let two =
        kiln_tests::rewrite(&good, sections::MATERIALS, |d| d[80..84].copy_from_slice(&2.0f32.to_le_bytes()));
    let f = KilnFile::from_bytes(&two, Checksums::Eager).unwrap();
    let e = SceneView::new(&f).map(|_| ()).expect_err("a coat of 2 accepted").to_string();
    assert!(e.contains("clear coat"), "{e}");
}

#[test]
fn damaged_dielectric_reflectance_is_refused() {
    use kiln_format::{Checksums, KilnFile, SceneView, sections};
    let dir = tempfile::tempdir().unwrap();
    let gltf = dir.path().join("floor.gltf");
    std::fs::write(&gltf, floor_gltf()).unwrap();
    std::fs::write(dir.path().join("floor.bin"), floor_bin()).unwrap();
    let good = compile(kiln_compiler::import::import(&gltf).unwrap(), fast_settings());
    let check = |b: &[u8]| {
        let f = KilnFile::from_bytes(b, Checksums::Eager).unwrap();
        SceneView::new(&f).map(|_| ()).map_err(|e| e.to_string())
    };
    assert_eq!(check(&good), Ok(()));
    // Word 1's high half is F90: 0x4000 is 2.0.
    let above_one =
        kiln_tests::rewrite(&good, sections::MATERIALS, |d| d[78..80].copy_from_slice(&[0x00, 0x40]));
    let e = check(&above_one).expect_err("F90 = 2 accepted");
    assert!(e.contains("dielectric reflectance"), "{e}");
    // Clear the flag (bit 4 of the flags at 68), keep the words.
    let unflagged = kiln_tests::rewrite(&good, sections::MATERIALS, |d| d[68] &= !16);
    let e = check(&unflagged).expect_err("words without the flag accepted");
    assert!(e.contains("dielectric reflectance"), "{e}");
}
