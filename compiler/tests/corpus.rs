//! The conformance corpus: real glTF sample models (tests/corpus/khronos, CC0) compiled with
//! `kiln compile` as a user would, the files read back, and what each asset means asserted
//! against values decoded here from the asset's own buffers (base64, little-endian floats): a
//! vertex colour present, flat face normals, a morphed position, a camera; and which untouched
//! samples `--strict` passes and why the others fail.

#[path = "util/run.rs"]
mod run;

use std::path::{Path, PathBuf};

use base64::Engine;
use kiln_format::read::KilnFile;
use kiln_format::scene::SceneView;
use run::kiln;

fn model(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/corpus/khronos")
        .join(name)
        .join(format!("{name}.gltf"))
}

/// Compiles `name` into `dir` and returns the file's bytes.
fn compiled(dir: &Path, name: &str, extra: &[&str]) -> Vec<u8> {
    let out = dir.join(format!("{name}.kiln"));
    let input = model(name);
    let mut args = vec!["compile", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "-q"];
    args.extend_from_slice(extra);
    kiln(dir, &args).expect(0);
    std::fs::read(out).unwrap()
}

/// Buffer `i` of the asset (a base64 data URI) and its JSON.
fn asset(name: &str) -> (serde_json::Value, Vec<Vec<u8>>) {
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(model(name)).unwrap()).unwrap();
    let buffers = json["buffers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| {
            let uri = b["uri"].as_str().unwrap();
            base64::engine::general_purpose::STANDARD.decode(uri.split_once(',').unwrap().1).unwrap()
        })
        .collect();
    (json, buffers)
}

/// The float VEC3 elements of accessor `a`.
fn vec3s(json: &serde_json::Value, buffers: &[Vec<u8>], a: usize) -> Vec<[f32; 3]> {
    let acc = &json["accessors"][a];
    let view = &json["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let buf = &buffers[view["buffer"].as_u64().unwrap() as usize];
    let start =
        view["byteOffset"].as_u64().unwrap_or(0) as usize + acc["byteOffset"].as_u64().unwrap_or(0) as usize;
    let stride = view["byteStride"].as_u64().unwrap_or(12) as usize;
    (0..acc["count"].as_u64().unwrap() as usize)
        .map(|i| {
            let o = start + i * stride;
            [0, 1, 2].map(|k| f32::from_le_bytes(buf[o + 4 * k..o + 4 * k + 4].try_into().unwrap()))
        })
        .collect()
}

#[test]
fn box_vertex_colors_keeps_its_colours() {
    // The model's colours are its positions (an RGB cube): every stored vertex's colour is its
    // position in unorm16.
    let d = tempfile::tempdir().unwrap();
    let bytes = compiled(d.path(), "BoxVertexColors", &[]);
    let file = KilnFile::from_bytes(&bytes, Default::default()).unwrap();
    let view = SceneView::new(&file).unwrap();
    assert_eq!(view.colors.len(), view.vertices.len());
    assert_eq!(view.vertices.len(), 24);
    for (v, c) in view.vertices.iter().zip(view.colors) {
        let want = [v.position[0], v.position[1], v.position[2], 1.0].map(|x| (x * 65535.0).round() as u16);
        assert_eq!(*c, want, "vertex at {:?}", v.position);
    }
}

#[test]
fn triangle_without_normals_is_flat() {
    let d = tempfile::tempdir().unwrap();
    let bytes = compiled(d.path(), "Triangle", &[]);
    let file = KilnFile::from_bytes(&bytes, Default::default()).unwrap();
    let view = SceneView::new(&file).unwrap();
    assert!(view.colors.is_empty(), "no COLOR_0: no colour section");
    let [a, b, c] = view.triangles[0].map(|i| glam::Vec3::from(view.vertices[i as usize].position));
    let face = (b - a).cross(c - a).normalize();
    for v in view.vertices {
        assert!((glam::Vec3::from(v.normal) - face).length() < 1e-6, "{:?} vs face {face}", v.normal);
    }
}

#[test]
fn simple_morph_sits_at_its_default_weights() {
    // Base shape + 0.5 × target 0 + 0.5 × target 1 (the mesh's weights), from the asset's bytes.
    let d = tempfile::tempdir().unwrap();
    let (json, buffers) = asset("SimpleMorph");
    let prim = &json["meshes"][0]["primitives"][0];
    let base = vec3s(&json, &buffers, prim["attributes"]["POSITION"].as_u64().unwrap() as usize);
    let targets: Vec<Vec<[f32; 3]>> = prim["targets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| vec3s(&json, &buffers, t["POSITION"].as_u64().unwrap() as usize))
        .collect();
    let weights: Vec<f32> =
        json["meshes"][0]["weights"].as_array().unwrap().iter().map(|w| w.as_f64().unwrap() as f32).collect();
    let bytes = compiled(d.path(), "SimpleMorph", &[]);
    let file = KilnFile::from_bytes(&bytes, Default::default()).unwrap();
    let view = SceneView::new(&file).unwrap();
    for (i, p) in base.iter().enumerate() {
        let want: [f32; 3] =
            [0, 1, 2].map(|k| p[k] + targets.iter().zip(&weights).map(|(t, w)| w * t[i][k]).sum::<f32>());
        assert!(
            view.vertices.iter().any(|v| (0..3).all(|k| (v.position[k] - want[k]).abs() < 1e-6)),
            "no vertex at {want:?}; stored {:?}",
            view.vertices.iter().map(|v| v.position).collect::<Vec<_>>()
        );
    }
}

#[test]
fn cameras_keeps_its_perspective_and_orthographic_cameras() {
    // yfov 0.7 rad from (0.5, 0.5, 3) looking down −z; then the orthographic one, xmag = ymag = 1
    // (stored with the equivalent field of view 2·atan(1) = 90° for manifest-1 readers).
    let d = tempfile::tempdir().unwrap();
    let bytes = compiled(d.path(), "Cameras", &[]);
    let file = KilnFile::from_bytes(&bytes, Default::default()).unwrap();
    let cams = file.manifest().unwrap().cameras;
    let c = &cams[0];
    assert!((c.vfov_degrees - 0.7f32.to_degrees()).abs() < 1e-4, "{c:?}");
    assert_eq!(c.position, [0.5, 0.5, 3.0]);
    assert!(c.target[2] < c.position[2] && c.target[0] == 0.5 && c.target[1] == 0.5, "{c:?}");
    let manifest = file.manifest().unwrap();
    assert_eq!(manifest.cameras.len(), 2);
    assert_eq!(
        manifest.orthographic,
        [kiln_format::manifest::OrthographicCamera { camera: 1, xmag: 1.0, ymag: 1.0 }]
    );
    assert_eq!(manifest.cameras[1].position, [0.5, 0.5, 3.0]);
    assert!((manifest.cameras[1].vfov_degrees - 90.0).abs() < 1e-4);
}

#[test]
fn strict_passes_untouched_samples_that_lose_nothing() {
    // Triangle, BoxVertexColors and Cameras lose nothing (no camera, no light: missing setup, not
    // data loss); SimpleMorph drops an animation: data loss.
    let d = tempfile::tempdir().unwrap();
    for (name, code, says) in [
        ("Triangle", 0, "[missing-setup]"),
        ("BoxVertexColors", 0, "[missing-setup]"),
        ("SimpleMorph", 1, "animation(s) not baked"),
        ("Cameras", 0, "[missing-setup]"),
    ] {
        let out = d.path().join(format!("{name}.kiln"));
        kiln(d.path(), &["compile", model(name).to_str().unwrap(), "-o", out.to_str().unwrap(), "--strict"])
            .expect(code)
            .says(says);
    }
}
