//! Hostile glTF inputs (issue 40), each built here: every one is refused with exit 1 and a
//! message naming the object and the fault, or compiled, within a bound on time and memory —
//! never a panic (exit 70), an abort or a hang.

// The builder is shared by several test files; this one leaves some of it unused.
#[allow(dead_code)]
#[path = "util/gltf.rs"]
mod gltf_builder;
#[path = "util/run.rs"]
mod run;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use gltf_builder::Gltf;
use run::Run;
use serde_json::json;

/// Wall-clock bound of one run (a debug build, beside other tests on few cores).
const LIMIT: Duration = Duration::from_secs(20);
/// Address-space bound of one run, in KiB (`ulimit -v`): 4 GiB.
const MEMORY_KIB: u64 = 4 << 20;

/// `kiln compile INPUT -o out.kiln EXTRA…` in `dir`, killed after [`LIMIT`] and run under
/// [`MEMORY_KIB`] of address space; a run past the limit fails the test.
fn compile(dir: &Path, input: &Path, extra: &[&str]) -> Run {
    // Small bakes: only the import is under test.
    let small = ["--shaft-variants", "none", "--brdf-lut-res", "8", "--shadow-res", "16"];
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg(format!("ulimit -v {MEMORY_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_kiln"))
        .args(["compile", input.to_str().unwrap(), "-o", "out.kiln"])
        .args(small)
        .args(extra)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = cmd.spawn().expect("kiln runs");
    // Drain both pipes on threads so that a chatty child cannot block on a full pipe.
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || std::io::read_to_string(&mut out).unwrap_or_default());
    let err = std::thread::spawn(move || std::io::read_to_string(&mut err).unwrap_or_default());
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > LIMIT {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("kiln ran past {LIMIT:?} on {}", input.display());
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let run = Run {
        // A signal (abort, stack overflow, out of memory) has no code: -1 fails every `expect`.
        code: status.code().unwrap_or(-1),
        stdout: out.join().unwrap(),
        stderr: err.join().unwrap(),
    };
    assert!(status.code().is_some(), "kiln was killed by a signal: {status:?}\n{run:#?}");
    run
}

/// A one-quad scene changed by `edit`.
fn quad_with(edit: impl FnOnce(&mut Gltf)) -> Gltf {
    let mut g = Gltf::quad();
    edit(&mut g);
    g
}

/// Writes `g` as `name.gltf` into `dir` and checks that compiling it is refused (exit 1) with
/// `message` on stderr.
fn refused(dir: &Path, mut g: Gltf, name: &str, message: &str) {
    let f = g.write(dir, name);
    compile(dir, &f, &[]).expect(1).says(message);
}

#[test]
fn primitive_naming_a_missing_accessor() {
    // The accessors array is empty while the primitive still names accessors 0 and 1: gltf-json's
    // validation indexed the accessors with POSITION's index and panicked.
    let d = tempfile::tempdir().unwrap();
    let empty = quad_with(|g| g.json["accessors"] = json!([]));
    let message = "mesh 0 primitive 0: attribute POSITION names accessor 0, but the file has 0 accessors";
    refused(d.path(), empty, "noacc", message);
    // The indices and a morph target are checked alike.
    let indices = quad_with(|g| g.json["meshes"][0]["primitives"][0]["indices"] = 7.into());
    refused(d.path(), indices, "noidx", "mesh 0 primitive 0: indices names accessor 7, but the file has 2");
    let target = quad_with(|g| {
        g.json["meshes"][0]["primitives"][0]["targets"] = json!([{"NORMAL": 0}, {"POSITION": 9}])
    });
    refused(d.path(), target, "notarget", "mesh 0 primitive 0: morph target 1 POSITION names accessor 9");
}

#[test]
fn image_without_uri_or_buffer_view() {
    let textured = |image: &dyn Fn(&mut Gltf) -> serde_json::Value| {
        quad_with(|g| {
            g.textured(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}), "unused.png");
            g.json["images"] = json!([image(g)]);
        })
    };
    // The gltf crate unwrapped the missing uri.
    let d = tempfile::tempdir().unwrap();
    let none = textured(&|_| json!({"name": "nothing"}));
    refused(d.path(), none, "noimg", "image 0 'nothing' has neither a uri nor a bufferView");
    // A buffer view without a MIME type: the gltf crate unwrapped the missing mimeType.
    let view = textured(&|g| json!({ "bufferView": g.view(b"\x89PNG\r\n\x1a\n", None) }));
    refused(d.path(), view, "nomime", "image 0 has a bufferView but no mimeType");
}

#[test]
fn camera_without_its_projection() {
    // `type` perspective with only an orthographic object: the gltf crate unwrapped the missing
    // perspective.
    let d = tempfile::tempdir().unwrap();
    let g = quad_with(|g| {
        let ortho = json!({"xmag": 1.0, "ymag": 1.0, "znear": 0.1, "zfar": 10.0});
        g.json["cameras"] = json!([{"type": "perspective", "orthographic": ortho}]);
        g.json["nodes"] = json!([{"mesh": 0}, {"camera": 0, "translation": [0.0, 0.0, 3.0]}]);
        g.json["scenes"][0]["nodes"] = json!([0, 1]);
    });
    refused(d.path(), g, "cam", "camera 0 has type perspective but no perspective object");
}

/// A quad under a chain of `depth` nodes, node `i` being `node(i)` (which names its children),
/// the last placing the quad.
fn chain(depth: usize, node: impl Fn(usize) -> serde_json::Value) -> Gltf {
    quad_with(|g| {
        let mut nodes: Vec<serde_json::Value> = (0..depth).map(node).collect();
        nodes.push(json!({"mesh": 0}));
        g.json["nodes"] = nodes.into();
    })
}

#[test]
fn ten_thousand_deep_node_chain() {
    // A parent→child chain deeper than the stack allows recursion for (5,000 worked, 10,000
    // overflowed it): the nodes are walked iteratively. Each level moves 1 mm along x.
    let d = tempfile::tempdir().unwrap();
    let f = chain(10_000, |i| json!({"children": [i + 1], "translation": [0.001, 0.0, 0.0]}))
        .write(d.path(), "deep");
    compile(d.path(), &f, &[]).expect(0);
    run::kiln(d.path(), &["verify", "out.kiln"]).expect(0);
    // The transforms compose through all 10,000 levels.
    let s = kiln_compiler::import::import(&f).unwrap();
    let x = s.vertices.iter().map(|v| v.position[0]).fold(f32::INFINITY, f32::min);
    assert!((x - 10.0).abs() < 1e-2, "the chain moved the quad to x = {x}, not 10");
}

#[test]
fn child_listed_twice_chained() {
    // Each node lists the next twice: not a cycle, but the walk doubled per level (2⁴⁰ visits).
    // glTF gives a node one parent; the file is refused at the first duplicate.
    let d = tempfile::tempdir().unwrap();
    let twice = chain(40, |i| json!({"children": [i + 1, i + 1]}));
    refused(d.path(), twice, "twice", "node 1 is listed twice among the children of node 0");
    // Two parents, each listing the child once.
    let two = quad_with(|g| {
        g.json["nodes"] = json!([{"children": [2]}, {"children": [2]}, {"mesh": 0}]);
        g.json["scenes"][0]["nodes"] = json!([0, 1]);
    });
    refused(d.path(), two, "two", "node 2 is a child of both node 0 and node 1");
}

#[test]
fn node_cycle_is_named() {
    // With one parent per node, a cycle is found before the walk, wherever it lies (this one is
    // not reachable from the scene).
    let d = tempfile::tempdir().unwrap();
    let g = quad_with(|g| {
        g.json["nodes"] = json!([{"mesh": 0}, {"children": [2]}, {"children": [3]}, {"children": [1]}]);
    });
    refused(d.path(), g, "cycle", "node hierarchy has a cycle through node");
}

/// A scene of one primitive whose POSITION accessor has no buffer view: `count` zeros, three of
/// them replaced by sparse values.
fn sparse_only_positions(count: u64) -> Gltf {
    let mut g = Gltf::new();
    let idx: Vec<u8> = [0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes()).collect();
    let val: Vec<u8> =
        [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|v| v.to_le_bytes()).collect();
    let iv = g.view(&idx, None);
    let vv = g.view(&val, None);
    let sparse = json!({"count": 3, "indices": {"bufferView": iv, "componentType": 5125}, "values": {"bufferView": vv}});
    let bounds = json!({"count": count, "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0], "sparse": sparse});
    let p = g.accessor(None, 5126, 0, "VEC3", bounds);
    g.json["meshes"] = json!([{"primitives": [{"attributes": {"POSITION": p}}]}]);
    g
}

#[test]
fn sparse_accessor_without_view_and_huge_count() {
    // count 2³¹−1 in a tiny file: reading it allocated 25 GB and aborted.
    let d = tempfile::tempdir().unwrap();
    let mut g = sparse_only_positions((1 << 31) - 1);
    let f = g.write(d.path(), "sparse");
    assert!(std::fs::metadata(&f).unwrap().len() < 4096);
    compile(d.path(), &f, &[])
        .expect(1)
        .says("mesh 0 primitive 0: POSITION accessor 0 has no buffer view")
        .says("2147483647 elements of 12 bytes");
    // The same in a GLB, whose binary chunk is the buffer.
    let f = g.write_glb(d.path(), "sparse");
    compile(d.path(), &f, &[]).expect(1).says("2147483647 elements of 12 bytes");
    // A modest sparse-only accessor still compiles (one triangle, the rest degenerate zeros).
    let f = sparse_only_positions(6).write(d.path(), "modest");
    compile(d.path(), &f, &[]).expect(0);
}

/// A quad of material `material`, which may use `KHR_materials_emissive_strength`.
fn quad_of(material: serde_json::Value) -> Gltf {
    quad_with(|g| {
        g.json["extensionsUsed"] = json!(["KHR_materials_emissive_strength"]);
        g.json["meshes"][0]["primitives"][0]["material"] = 0.into();
        g.json["materials"] = json!([material]);
    })
}

#[test]
fn unphysical_material_factors_are_clamped_with_warnings() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_of(json!({
        "name": "hot",
        "pbrMetallicRoughness": {"baseColorFactor": [-1.0, 0.5, 2.0, 1.0], "metallicFactor": -5.0, "roughnessFactor": 3.0},
        "emissiveFactor": [-1.0, 0.25, 0.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": -2.0}},
    }))
    .write(d.path(), "mat");
    compile(d.path(), &f, &[])
        .expect(0)
        .says("material 'hot': pbrMetallicRoughness.baseColorFactor [-1.0, 0.5, 2.0, 1.0] is outside [0, 1]; clamped to [0.0, 0.5, 1.0, 1.0]")
        .says("material 'hot': pbrMetallicRoughness.metallicFactor -5 is outside [0, 1]; clamped to 0")
        .says("material 'hot': pbrMetallicRoughness.roughnessFactor 3 is outside [0, 1]; clamped to 1")
        .says("material 'hot': emissiveFactor [-1.0, 0.25, 0.0] is negative; clamped to [0.0, 0.25, 0.0]")
        .says("material 'hot': KHR_materials_emissive_strength.emissiveStrength -2 is negative; clamped to 0")
        .says("[data-loss]");
    // Clamping changes the asset: --strict fails on it.
    compile(d.path(), &f, &["--strict"]).expect(1).says("class data-loss");
    let s = kiln_compiler::import::import(&f).unwrap();
    let m = &s.materials[0].gpu;
    assert_eq!(m.base_color, [0.0, 0.5, 1.0, 1.0]);
    assert_eq!((m.metallic, m.roughness, m.emission), (0.0, 1.0, [0.0; 3]));

    // Emission past f32's range (factor × strength) is refused, naming both fields.
    let inf = quad_of(json!({
        "name": "inf",
        "emissiveFactor": [1e38, 0.0, 0.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e38}},
    }));
    let message = "material 'inf': emissiveFactor [1e38, 0.0, 0.0] × KHR_materials_emissive_strength.emissiveStrength 1e38 is not finite";
    refused(d.path(), inf, "inf", message);
}

#[test]
fn unphysical_ior_and_specular_are_clamped_with_warnings() {
    let d = tempfile::tempdir().unwrap();
    let f = quad_with(|g| {
        g.json["extensionsUsed"] = json!(["KHR_materials_ior", "KHR_materials_specular"]);
        g.json["meshes"][0]["primitives"][0]["material"] = 0.into();
        g.json["materials"] = json!([{
            "name": "odd",
            "extensions": {
                "KHR_materials_ior": {"ior": -2.0},
                "KHR_materials_specular": {"specularFactor": 1.5, "specularColorFactor": [-1.0, 2.0, 1.0]},
            },
        }]);
    })
    .write(d.path(), "odd");
    compile(d.path(), &f, &[])
        .expect(0)
        .says("material 'odd': KHR_materials_ior.ior -2 is below 1; clamped to 1")
        .says("material 'odd': KHR_materials_specular.specularFactor 1.5 is outside [0, 1]; clamped to 1")
        .says("material 'odd': KHR_materials_specular.specularColorFactor [-1.0, 2.0, 1.0] is negative; clamped to [0.0, 2.0, 1.0]");
    // ior 1 after clamping: no reflection at normal incidence, F90 the clamped factor.
    let s = kiln_compiler::import::import(&f).unwrap();
    assert_eq!(s.materials[0].gpu.dielectric(), ([0.0; 3], 1.0));
    // ior 0, which the specification allows: F0 = 1 (times the colour, at most 1).
    let zero = quad_with(|g| {
        g.json["extensionsUsed"] = json!(["KHR_materials_ior"]);
        g.json["meshes"][0]["primitives"][0]["material"] = 0.into();
        g.json["materials"] = json!([{"name": "zero", "extensions": {"KHR_materials_ior": {"ior": 0.0}}}]);
    })
    .write(d.path(), "zero");
    let s = kiln_compiler::import::import(&zero).unwrap();
    assert_eq!(s.materials[0].gpu.dielectric(), ([1.0; 3], 1.0));
}

#[test]
fn malformed_morph_target_tangents() {
    // TANGENT targets are not applied, but reading the targets built an iterator over them: an
    // empty accessor underflowed `count - 1` inside the gltf crate.
    let d = tempfile::tempdir().unwrap();
    let g = quad_with(|g| {
        let t = g.accessor(Some(0), 5126, 0, "VEC3", json!({}));
        g.json["meshes"][0]["primitives"][0]["targets"] = json!([{ "TANGENT": t }]);
        g.json["meshes"][0]["weights"] = json!([0.5]);
    });
    refused(d.path(), g, "tangent", "mesh 0 primitive 0: morph target 0 TANGENT accessor 2 has no elements");
}

#[test]
fn animations_the_gltf_crate_cannot_parse_are_dropped_with_a_warning() {
    let d = tempfile::tempdir().unwrap();
    // A channel target without `node` (the spec allows it: KHR_animation_pointer names the
    // target instead); the gltf crate's reader requires the field.
    let pointer = |g: &mut Gltf| {
        g.json["animations"] = json!([{
            "channels": [{"sampler": 0, "target": {"path": "pointer",
                "extensions": {"KHR_animation_pointer": {"pointer": "/nodes/0/translation"}}}}],
            "samplers": [{"input": 0, "output": 0}]
        }]);
    };
    let mut g = quad_with(pointer);
    let f = g.write(d.path(), "pointer");
    compile(d.path(), &f, &[]).expect(0).says("1 animation(s) dropped unread").says("missing field `node`");
    let f = g.write_glb(d.path(), "pointer");
    compile(d.path(), &f, &[]).expect(0).says("1 animation(s) dropped unread");
    // Something else that does not parse is still refused, whatever the animations.
    let mut g = quad_with(|g| {
        pointer(g);
        g.json["meshes"] = json!("not a list");
    });
    let f = g.write(d.path(), "broken");
    compile(d.path(), &f, &[]).expect(1).says("not a valid glTF 2.0 file");
}
