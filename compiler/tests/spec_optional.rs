//! What glTF 2.0 leaves optional may be left out: a file that uses most of the specification
//! (materials with every texture slot, samplers, cameras of both kinds, an animation, a skin,
//! sparse and morph-target accessors, names, extras, an extension kiln does not know) imports
//! with every optional property removed, one at a time. The required properties are the
//! specification's (glTF 2.0, the JSON schema's `required` lists), spelled out here; data kiln
//! does not use (animations, skins, unknown extensions) must never make a file fail.

// The builder serves several test files; this one writes .gltf only.
#[allow(dead_code)]
#[path = "util/gltf.rs"]
mod gltf_builder;

use gltf_builder::Gltf;
use serde_json::{Value, json};

/// Required properties by the path of their object, `[]` for any array element (glTF 2.0's JSON
/// schema). Removing one of these may make a file invalid; every other property is optional.
const REQUIRED: &[&str] = &[
    "asset",
    "asset.version",
    "accessors[].componentType",
    "accessors[].count",
    "accessors[].type",
    "accessors[].sparse.count",
    "accessors[].sparse.indices",
    "accessors[].sparse.indices.bufferView",
    "accessors[].sparse.indices.componentType",
    "accessors[].sparse.values",
    "accessors[].sparse.values.bufferView",
    "animations[].channels",
    "animations[].samplers",
    "animations[].channels[].sampler",
    "animations[].channels[].target",
    "animations[].channels[].target.path",
    "animations[].samplers[].input",
    "animations[].samplers[].output",
    "buffers[].byteLength",
    "bufferViews[].buffer",
    "bufferViews[].byteLength",
    "cameras[].type",
    "cameras[].perspective",
    "cameras[].perspective.yfov",
    "cameras[].perspective.znear",
    "cameras[].orthographic",
    "cameras[].orthographic.xmag",
    "cameras[].orthographic.ymag",
    "cameras[].orthographic.zfar",
    "cameras[].orthographic.znear",
    "meshes[].primitives",
    "meshes[].primitives[].attributes",
    "materials[].pbrMetallicRoughness.baseColorTexture.index",
    "materials[].pbrMetallicRoughness.metallicRoughnessTexture.index",
    "materials[].normalTexture.index",
    "materials[].occlusionTexture.index",
    "materials[].emissiveTexture.index",
    "skins[].joints",
    // In a .gltf a buffer without `uri` has no bytes (only a GLB's first buffer may omit it),
    // and an image needs its `uri` or a `bufferView`.
    "buffers[].uri",
    "images[].uri",
    // Optional, but leaving one out changes what the file means rather than leaving a default:
    // the top-level arrays are indexed by the rest of the file (without them the references
    // dangle), and a view's offset moves the bytes its accessors read (kiln then refuses the
    // indices it finds out of range, as it should).
    "accessors",
    "bufferViews",
    "buffers",
    "cameras",
    "images",
    "materials",
    "meshes",
    "nodes",
    "samplers",
    "scenes",
    "skins",
    "textures",
    "bufferViews[].byteOffset",
];

/// A file that uses most of what glTF 2.0 offers.
fn rich(dir: &std::path::Path) -> Gltf {
    let mut g = Gltf::quad();
    g.textured(
        json!({
            "name": "m",
            "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 0.5, 0.5, 1.0],
                "baseColorTexture": {"index": 0, "texCoord": 0},
                "metallicFactor": 0.5,
                "roughnessFactor": 0.5,
                "metallicRoughnessTexture": {"index": 0}
            },
            "normalTexture": {"index": 0, "scale": 0.5},
            "occlusionTexture": {"index": 0, "strength": 0.5},
            "emissiveTexture": {"index": 0},
            "emissiveFactor": [0.5, 0.5, 0.5],
            "alphaMode": "MASK",
            "alphaCutoff": 0.25,
            "doubleSided": true,
            "extras": {"note": 1}
        }),
        "t.png",
    );
    image::RgbaImage::from_pixel(4, 4, image::Rgba([200, 100, 50, 255])).save(dir.join("t.png")).unwrap();
    g.json["textures"] = json!([{"source": 0, "sampler": 0, "name": "t"}]);
    g.json["images"] = json!([{"uri": "t.png", "mimeType": "image/png", "name": "i"}]);
    g.json["samplers"] =
        json!([{"magFilter": 9729, "minFilter": 9987, "wrapS": 33648, "wrapT": 33071, "name": "s"}]);
    // Normals, a morph target with sparse deltas, and a second mesh placed by a skinned node.
    let normals: Vec<u8> = [[0.0f32, 0.0, 1.0]; 4].iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let nv = g.view(&normals, None);
    let n = g.accessor(Some(nv), 5126, 4, "VEC3", json!({"normalized": false, "name": "normals"}));
    let sparse_idx = g.view(&1u32.to_le_bytes(), None);
    let sparse_val =
        g.view(&[0.0f32, 0.0, 0.25].iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>(), None);
    let delta = g.accessor(
        None,
        5126,
        4,
        "VEC3",
        json!({"min": [0.0, 0.0, 0.0], "max": [0.0, 0.0, 0.25], "sparse": {"count": 1,
            "indices": {"bufferView": sparse_idx, "byteOffset": 0, "componentType": 5125},
            "values": {"bufferView": sparse_val, "byteOffset": 0}}}),
    );
    {
        let prim = &mut g.json["meshes"][0]["primitives"][0];
        prim["attributes"]["NORMAL"] = n.into();
        prim["targets"] = json!([{"POSITION": delta}]);
        prim["mode"] = 4.into();
        prim["extras"] = json!({});
    }
    g.json["meshes"][0]["weights"] = json!([0.5]);
    g.json["meshes"][0]["name"] = "quad".into();
    // Animation: node 1's translation over two keys.
    let times = g.view(&[0.0f32, 1.0].iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>(), None);
    let input = g.accessor(Some(times), 5126, 2, "SCALAR", json!({"min": [0.0], "max": [1.0]}));
    let moves: Vec<u8> = [0.0f32, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|v| v.to_le_bytes()).collect();
    let mv = g.view(&moves, None);
    let output = g.accessor(Some(mv), 5126, 2, "VEC3", json!({}));
    g.json["animations"] = json!([{"name": "a",
        "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}],
        "samplers": [{"input": input, "output": output, "interpolation": "LINEAR"}]}]);
    // Skin: node 3 skins mesh 0 with joint node 1 (identity inverse bind matrix).
    let ibm: Vec<u8> = glam::Mat4::IDENTITY.to_cols_array().iter().flat_map(|v| v.to_le_bytes()).collect();
    let ibv = g.view(&ibm, None);
    let ib = g.accessor(Some(ibv), 5126, 1, "MAT4", json!({}));
    g.json["skins"] = json!([{"joints": [1], "inverseBindMatrices": ib, "skeleton": 1, "name": "sk"}]);
    g.json["cameras"] = json!([
        {"type": "perspective", "name": "p", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100.0, "aspectRatio": 1.5}},
        {"type": "orthographic", "orthographic": {"xmag": 2.0, "ymag": 1.5, "zfar": 50.0, "znear": 0.01}}
    ]);
    g.json["nodes"] = json!([
        {"name": "root", "children": [1, 2, 4], "matrix": [1.0,0.0,0.0,0.0, 0.0,1.0,0.0,0.0, 0.0,0.0,1.0,0.0, 0.0,0.0,0.0,1.0]},
        {"name": "mover", "mesh": 0, "translation": [0.0, 0.0, 0.5], "rotation": [0.0, 0.0, 0.0, 1.0], "scale": [1.0, 1.0, 1.0], "weights": [0.25]},
        {"name": "eye", "camera": 0, "translation": [0.0, 0.0, 4.0]},
        {"name": "skinned", "mesh": 0, "skin": 0},
        {"name": "top", "camera": 1, "translation": [0.0, 4.0, 0.0], "rotation": [-0.70710677, 0.0, 0.0, 0.70710677]}
    ]);
    g.json["scenes"] = json!([{"name": "s", "nodes": [0, 3], "extras": {"x": 1}}]);
    g.json["scene"] = 0.into();
    g.json["asset"] =
        json!({"version": "2.0", "generator": "kiln test", "copyright": "CC0", "minVersion": "2.0"});
    g.json["extensionsUsed"] = json!(["EXT_kiln_unknown"]);
    g.json["extensions"] = json!({"EXT_kiln_unknown": {"payload": [1, 2, 3]}});
    g.json["extras"] = json!({"tool": "test"});
    g.json["bufferViews"][0]["name"] = "positions".into();
    g.json["accessors"][0]["name"] = "p".into();
    g
}

/// Every object property's path, as `REQUIRED` spells them, with its JSON pointer.
fn properties(v: &Value, path: &str, pointer: &str, out: &mut Vec<(String, String)>) {
    match v {
        Value::Object(o) => {
            for (k, child) in o {
                let p = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
                let ptr = format!("{pointer}/{k}");
                out.push((p.clone(), ptr.clone()));
                properties(child, &p, &ptr, out);
            }
        }
        Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                properties(child, &format!("{path}[]"), &format!("{pointer}/{i}"), out);
            }
        }
        _ => {}
    }
}

/// Removes the property at `pointer`.
fn remove(v: &mut Value, pointer: &str) {
    let (parent, key) = pointer.rsplit_once('/').unwrap();
    let parent = if parent.is_empty() { &mut *v } else { v.pointer_mut(parent).unwrap() };
    parent.as_object_mut().unwrap().remove(key);
}

#[test]
fn every_optional_property_may_be_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let mut g = rich(dir.path());
    let path = g.write(dir.path(), "rich");
    let whole = kiln_compiler::import::import(&path).expect("the whole file imports");
    assert!(whole.triangles.len() >= 4, "both placements of the quad: {}", whole.triangles.len());
    let json: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let mut props = Vec::new();
    properties(&json, "", "", &mut props);
    let optional: Vec<&(String, String)> =
        props.iter().filter(|(p, _)| !REQUIRED.contains(&p.as_str())).collect();
    assert!(
        optional.len() > 80,
        "the file exercises the specification: {} optional properties",
        optional.len()
    );
    let mut failures = Vec::new();
    for (i, (prop, pointer)) in optional.iter().enumerate() {
        let mut j = json.clone();
        remove(&mut j, pointer);
        let file = dir.path().join(format!("without{i}.gltf"));
        std::fs::write(&file, serde_json::to_vec(&j).unwrap()).unwrap();
        if let Err(e) = kiln_compiler::import::import(&file) {
            failures.push(format!("without {prop} ({pointer}): {e}"));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} optional properties failed the import:\n{}",
        failures.len(),
        optional.len(),
        failures.join("\n")
    );
}
