//! A corpus of broken inputs, generated here: each gives its documented error or warning and
//! none panics.

#[path = "util/gltf.rs"]
mod gltf_builder;
#[path = "util/run.rs"]
mod run;

use gltf_builder::Gltf;
use run::kiln;
use serde_json::json;

fn compile(dir: &std::path::Path, input: &std::path::Path, extra: &[&str]) -> run::Run {
    let mut args = vec!["compile", input.to_str().unwrap(), "-o", "out.kiln"];
    args.extend_from_slice(extra);
    kiln(dir, &args)
}

fn quad_with(dir: &std::path::Path, name: &str, edit: impl FnOnce(&mut Gltf)) -> std::path::PathBuf {
    let mut g = Gltf::quad();
    edit(&mut g);
    g.write(dir, name)
}

#[test]
fn nan_position() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    let p = g.positions(&[[0.0, 0.0, 0.0], [2.0, f32::NAN, 3.0], [0.0, 1.0, 0.0]]);
    g.mesh(json!({"attributes": {"POSITION": p}}));
    // Behind a rotation that would smear the NaN over every coordinate: the message quotes the
    // accessor's own values.
    g.json["nodes"][0]["rotation"] = json!([0.0, 0.6, 0.0, 0.8]);
    let f = g.write(d.path(), "nan");
    compile(d.path(), &f, &[])
        .expect(1)
        .says("mesh 0 primitive 0: POSITION accessor 0 element 1 is not finite: [2.0, NaN, 3.0]");
}

#[test]
fn huge_position() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    let p = g.positions(&[[0.0, 0.0, 0.0], [1e30, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    g.mesh(json!({"attributes": {"POSITION": p}}));
    let f = g.write(d.path(), "huge");
    compile(d.path(), &f, &[]).expect(1).says(
        "element 1 (accessor value [1e30, 0.0, 0.0]) after its node transform is [1e30, 0.0, 0.0], outside the supported range",
    );
}

#[test]
fn index_out_of_range() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    let p = g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let i = g.indices(&[0, 1, 7]);
    g.mesh(json!({"attributes": {"POSITION": p}, "indices": i}));
    let f = g.write(d.path(), "idx");
    compile(d.path(), &f, &[]).expect(1).says("indices accessor 1 element 2 is 7, but there are 3 vertices");
}

#[test]
fn truncated_bin() {
    let d = tempfile::tempdir().unwrap();
    let f = Gltf::quad().write(d.path(), "t");
    let bin = d.path().join("t.bin");
    let bytes = std::fs::read(&bin).unwrap();
    std::fs::write(&bin, &bytes[..bytes.len() - 5]).unwrap();
    compile(d.path(), &f, &[]).expect(1).says("buffer 0 ('t.bin') has").says("truncated");
}

#[test]
fn missing_bin() {
    let d = tempfile::tempdir().unwrap();
    let f = Gltf::quad().write(d.path(), "m");
    std::fs::remove_file(d.path().join("m.bin")).unwrap();
    compile(d.path(), &f, &[]).expect(1).says("buffer 0 ('m.bin'): cannot read");
}

#[test]
fn bad_data_uri() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::quad();
    let f = g.write(d.path(), "u");
    Gltf::set_buffer_uri(&f, "data:application/octet-stream;base64,@@not base64@@");
    compile(d.path(), &f, &[]).expect(1).says("malformed base64");
}

#[test]
fn missing_image_warns_and_strict_refuses() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(d.path(), "img", |g| {
        g.textured(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}), "nowhere.png")
    });
    let run = compile(d.path(), &f, &[]);
    run.expect(0).says("warning:").says("image 'nowhere.png': cannot read").says("placeholder");
    kiln(d.path(), &["verify", "out.kiln"]).expect(0);
    compile(d.path(), &f, &["--strict"]).expect(1).says("--strict").says("class data-loss");
}

#[test]
fn warnings_have_classes_and_strict_fails_on_data_loss_only() {
    // A quad without camera or light: two missing-setup warnings and nothing lost.
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(d.path(), "bare", |_| {});
    compile(d.path(), &f, &["--report", "r.json"])
        .expect(0)
        .says("no camera in the asset or sidecar")
        .says("[missing-setup]");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("r.json")).unwrap()).unwrap();
    let classes: Vec<&str> =
        report["warnings"].as_array().unwrap().iter().map(|w| w["class"].as_str().unwrap()).collect();
    assert_eq!(classes, ["missing-setup", "missing-setup"], "{report}");
    compile(d.path(), &f, &["--strict"]).expect(0);
    compile(d.path(), &f, &["--strict", "-W", "missing-setup=error"]).expect(1).says("class missing-setup");
    let quiet = compile(d.path(), &f, &["-W", "missing-setup=ignore"]);
    assert!(!quiet.expect(0).stderr.contains("warning:"), "{}", quiet.stderr);
    // A missing image is data loss: --strict fails unless -W relaxes it again.
    let g = quad_with(d.path(), "img", |g| {
        g.textured(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}), "nowhere.png")
    });
    compile(d.path(), &g, &["--strict", "-W", "data-loss=warn"]).expect(0).says("[data-loss]");
    compile(d.path(), &g, &["-W", "data-loss"]).expect(2).says("CLASS=LEVEL");
    compile(d.path(), &g, &["-W", "perf=error"]).expect(2).says("no warning class 'perf'");
}

#[test]
fn undecodable_image_warns() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("junk.png"), b"\x89PNG\r\n\x1a\nthis is not a png").unwrap();
    let f = quad_with(d.path(), "junk", |g| g.textured(json!({"normalTexture": {"index": 0}}), "junk.png"));
    compile(d.path(), &f, &[]).expect(0).says("image 'junk.png': cannot decode");
}

#[test]
fn empty_mesh() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    g.json["meshes"] = json!([{"primitives": []}]);
    let f = g.write(d.path(), "empty");
    compile(d.path(), &f, &[]).expect(1).says("no triangles");
}

#[test]
fn points_and_lines_only() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    let p = g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    g.json["meshes"] = json!([{"primitives": [{"attributes": {"POSITION": p}, "mode": 0}, {"attributes": {"POSITION": p}, "mode": 1}]}]);
    let f = g.write(d.path(), "pts");
    compile(d.path(), &f, &[])
        .expect(1)
        .says("mode Points has no triangles; skipped")
        .says("mode Lines")
        .says("no triangles");
}

#[test]
fn absurd_accessor_count() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(d.path(), "absurd", |g| {
        g.json["accessors"][0]["count"] = 1_000_000_000u64.into();
    });
    compile(d.path(), &f, &[]).expect(1).says("POSITION accessor 0").says("do not fit in buffer view");
}

#[test]
fn wrong_accessor_type() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(d.path(), "type", |g| {
        g.json["accessors"][0]["type"] = "VEC2".into();
    });
    compile(d.path(), &f, &[]).expect(1).says("POSITION accessor 0 has type Vec2");
}

#[test]
fn stride_smaller_than_element() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(d.path(), "stride", |g| {
        g.json["bufferViews"][0]["byteStride"] = 4.into();
    });
    compile(d.path(), &f, &[]).expect(1);
}

#[test]
fn buffer_view_past_buffer() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(d.path(), "view", |g| {
        g.json["bufferViews"][1]["byteOffset"] = 4000.into();
    });
    compile(d.path(), &f, &[]).expect(1);
}

#[test]
fn sparse_index_out_of_range() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(d.path(), "sparse", |g| {
        let idx = g.view(&9u32.to_le_bytes(), None);
        let val = g.view(&[0u8; 12], None);
        g.json["accessors"][0]["sparse"] = json!({"count": 1, "indices": {"bufferView": idx, "componentType": 5125}, "values": {"bufferView": val}});
    });
    compile(d.path(), &f, &[]).expect(1).says("sparse index 0 is 9");
}

#[test]
fn node_cycle() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(d.path(), "cycle", |g| {
        g.json["nodes"] = json!([{"mesh": 0, "children": [1]}, {"children": [0]}]);
    });
    compile(d.path(), &f, &[]).expect(1);
}

#[test]
fn unsupported_required_extension() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(d.path(), "ext", |g| {
        g.json["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
        g.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    });
    compile(d.path(), &f, &[]).expect(3).says("KHR_draco_mesh_compression");
}

#[test]
fn external_url() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::quad();
    let f = g.write(d.path(), "url");
    Gltf::set_buffer_uri(&f, "https://example.com/scene.bin");
    compile(d.path(), &f, &[]).expect(1).says("external URLs are not fetched");
}

#[test]
fn not_json() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("garbage.gltf");
    std::fs::write(&f, b"{ this is not json").unwrap();
    compile(d.path(), &f, &[]).expect(1).says("not a valid glTF 2.0 file");
}

#[test]
fn truncated_glb() {
    let d = tempfile::tempdir().unwrap();
    let f = Gltf::quad().write_glb(d.path(), "t");
    let bytes = std::fs::read(&f).unwrap();
    std::fs::write(&f, &bytes[..bytes.len() - 20]).unwrap();
    compile(d.path(), &f, &[]).expect(1);
}

#[test]
fn all_degenerate() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    let p = g.positions(&[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]]);
    g.mesh(json!({"attributes": {"POSITION": p}}));
    let f = g.write(d.path(), "deg");
    compile(d.path(), &f, &[]).expect(1).says("1 degenerate").says("all were degenerate");
}

#[test]
fn missing_input_and_directory() {
    let d = tempfile::tempdir().unwrap();
    compile(d.path(), &d.path().join("nope.gltf"), &[]).expect(4);
    std::fs::create_dir(d.path().join("dir.gltf")).unwrap();
    compile(d.path(), &d.path().join("dir.gltf"), &[]).expect(4).says("not a regular file");
}

fn obj(d: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = d.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn obj_face_with_missing_vertex() {
    let d = tempfile::tempdir().unwrap();
    let f = obj(d.path(), "f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
    compile(d.path(), &f, &[])
        .expect(1)
        .says("f.obj:5: face vertex 3 refers to position 9, but only 3 are defined");
}

#[test]
fn obj_negative_index_out_of_range() {
    let d = tempfile::tempdir().unwrap();
    let f = obj(d.path(), "n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
    compile(d.path(), &f, &[]).expect(1).says("n.obj:4:").says("refers to position -4");
}

#[test]
fn obj_two_vertex_face() {
    let d = tempfile::tempdir().unwrap();
    let f = obj(d.path(), "two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n");
    compile(d.path(), &f, &[]).expect(1).says("two.obj:3: face has 2 vertices");
}

#[test]
fn obj_nan_vertex() {
    let d = tempfile::tempdir().unwrap();
    let f = obj(d.path(), "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    compile(d.path(), &f, &[]).expect(1).says("nan.obj:2: vertex position");
}

#[test]
fn obj_missing_mtl_warns() {
    let d = tempfile::tempdir().unwrap();
    let f = obj(d.path(), "m.obj", "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
    compile(d.path(), &f, &[])
        .expect(0)
        .says("material library gone.mtl cannot be read")
        .says("default material");
}

#[test]
fn obj_without_faces() {
    let d = tempfile::tempdir().unwrap();
    let f = obj(d.path(), "e.obj", "# nothing\nv 0 0 0\n");
    compile(d.path(), &f, &[]).expect(1).says("has no faces");
}

/// Every table of the sidecar, with a minimal valid body: the unknown-key test below runs over
/// this list, and `sidecar_tables_are_all_listed` fails when `Sidecar` gains a table that is not
/// here.
const SIDECAR_TABLES: [(&str, &str, &str); 6] = [
    ("camera", "[camera]", "position = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n"),
    ("light", "[[light]]", "kind = \"point\"\nposition = [0.0, 1.0, 0.0]\nintensity = 1.0\n"),
    ("sky", "[sky]", "radiance = [0.1, 0.1, 0.1]\n"),
    ("medium", "[[medium]]", "min = [0.0, 0.0, -1.0]\nmax = [1.0, 1.0, 1.0]\nsigma_s = [0.01, 0.01, 0.01]\n"),
    ("material", "[material.\"default\"]", "roughness = 0.5\n"),
    ("bake", "[bake]", "bvh_preset = \"fast\"\n"),
];

#[test]
fn sidecar_tables_compile_as_listed() {
    // The bodies are valid, so that the misspelled key below is the only fault.
    for (_, header, body) in SIDECAR_TABLES {
        let d = tempfile::tempdir().unwrap();
        let f = Gltf::quad().write(d.path(), "s");
        std::fs::write(d.path().join("s.toml"), format!("{header}\n{body}")).unwrap();
        // Small bakes: only the sidecar is under test here.
        let small = ["--shaft-variants", "none", "--brdf-lut-res", "8", "--shadow-res", "16"];
        compile(d.path(), &f, &[&["--config", "s.toml"][..], &small].concat()).expect(0);
    }
}

#[test]
fn sidecar_unknown_key_is_named_in_every_table() {
    for (k, (_, header, body)) in SIDECAR_TABLES.iter().enumerate() {
        // The next table follows, so that the message must name the right one.
        let (_, next_header, next_body) = SIDECAR_TABLES[(k + 1) % SIDECAR_TABLES.len()];
        for misspelled in ["colour = [1.0, 1.0, 1.0]", "fov = 40.0"] {
            let d = tempfile::tempdir().unwrap();
            let f = Gltf::quad().write(d.path(), "s");
            let text = format!("{header}\n{body}{misspelled}\n\n{next_header}\n{next_body}");
            std::fs::write(d.path().join("s.toml"), &text).unwrap();
            let key = misspelled.split(' ').next().unwrap();
            compile(d.path(), &f, &["--config", "s.toml"])
                .expect(1)
                .says(&format!("in {header}:"))
                .says(&format!("unknown field `{key}`"));
        }
    }
}

#[test]
fn sidecar_tables_are_all_listed() {
    // Serde lists the tables `Sidecar` accepts when it refuses an unknown one.
    let err = kiln_compiler::import::sidecar::Sidecar::parse("[no_such_table]\n").unwrap_err();
    let expected = err.split("expected one of").nth(1).unwrap_or_else(|| panic!("no table list in {err:?}"));
    let accepted: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    let listed: Vec<&str> = SIDECAR_TABLES.iter().map(|(name, ..)| *name).collect();
    assert_eq!(accepted, listed, "Sidecar's tables and SIDECAR_TABLES differ: {err}");
}

#[test]
fn sidecar_rect_light_needs_size() {
    let d = tempfile::tempdir().unwrap();
    let f = Gltf::quad().write(d.path(), "s");
    std::fs::write(
        d.path().join("s.toml"),
        "[[light]]\nkind = \"rect\"\nposition = [0.0, 1.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\nright = [1.0, 0.0, 0.0]\nintensity = 1.0\n",
    )
    .unwrap();
    compile(d.path(), &f, &["--config", "s.toml"]).expect(1).says("light 1 (Rect): `size`");
}

#[test]
fn sidecar_unknown_material() {
    let d = tempfile::tempdir().unwrap();
    let f = Gltf::quad().write(d.path(), "s");
    std::fs::write(d.path().join("s.toml"), "[material.lamp]\nemission = [1.0, 1.0, 1.0]\n").unwrap();
    compile(d.path(), &f, &["--config", "s.toml"]).expect(1).says("material \"lamp\" is not in the scene");
}
