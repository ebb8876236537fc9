//! Import of glTF's material extensions and alpha modes: `KHR_materials_transmission` and
//! `KHR_materials_clearcoat` read with their textures (bad payloads only warned about), and
//! blended materials whose alpha is 1 everywhere made opaque.

#[allow(dead_code)] // Its GLB helpers serve other tests.
#[path = "util/gltf.rs"]
mod gltf_builder;

use gltf_builder::{Gltf, write_white_png};
use kiln_compiler::import::import;
use kiln_compiler::ir::{Scene, TextureRole};
use kiln_format::manifest::Wrap;
use kiln_format::sections::{MaterialFlags, NO_TEXTURE};
use serde_json::json;

/// Copies the first mesh's first primitive once per material of `g`, each copy using its own.
fn one_primitive_per_material(g: &mut Gltf) {
    let prim = g.json["meshes"][0]["primitives"][0].clone();
    let prims: Vec<_> = (0..g.json["materials"].as_array().map_or(0, Vec::len))
        .map(|m| {
            let mut p = prim.clone();
            p["material"] = m.into();
            p
        })
        .collect();
    g.json["meshes"][0]["primitives"] = json!(prims);
}

/// KHR_materials_transmission is read into the material's transmission (format 1.9), whatever
/// its alpha mode (a blended material keeps its alpha as coverage, a masked one its mask), with
/// its texture through its KHR_texture_transform; a factor above 1 is clamped with a warning.
/// (Its shading is checked against Mitsuba in tests/mitsuba.rs and against a closed form in
/// tests/render/reference.rs.)
#[test]
fn transmission_is_read_with_its_texture() {
    let d = tempfile::tempdir().unwrap();
    write_white_png(d.path());
    let mut g = Gltf::quad();
    let t = |v: serde_json::Value| json!({ "KHR_materials_transmission": v });
    g.textured(
        json!({"name": "paper", "extensions": t(json!({
            "transmissionFactor": 0.6,
            "transmissionTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [2.0, 3.0]}}}
        }))}),
        "white.png",
    );
    g.json["extensionsUsed"] = json!(["KHR_materials_transmission", "KHR_texture_transform"]);
    let mut materials = g.json["materials"].as_array().unwrap().clone();
    materials.extend([
        json!({"name": "glass", "extensions": t(json!({"transmissionFactor": 0.75}))}),
        json!({"name": "tinted", "alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 0.5]}, "extensions": t(json!({"transmissionFactor": 0.5}))}),
        json!({"name": "masked", "alphaMode": "MASK", "extensions": t(json!({"transmissionFactor": 0.5}))}),
        json!({"name": "loud", "extensions": t(json!({"transmissionFactor": 2.5}))}),
        json!({"name": "none", "extensions": t(json!({"transmissionFactor": 0.0}))}),
    ]);
    g.json["materials"] = json!(materials);
    one_primitive_per_material(&mut g);
    let s = import(&g.write(d.path(), "t")).unwrap();
    let m = |n: &str| s.materials.iter().find(|m| m.name == n).unwrap().gpu;
    let mode = |g: kiln_format::sections::GpuMaterial| g.flags >> MaterialFlags::ALPHA_MODE_SHIFT & 3;
    use kiln_format::sections::AlphaMode;
    let paper = m("paper");
    assert_eq!(paper.transmission, 0.6);
    assert_ne!(paper.transmission_texture, NO_TEXTURE);
    // The texture's transform is the material's mapping, baked into the coordinates.
    assert_eq!(s.uvs[..4], [[0.0, 0.0], [2.0, 0.0], [2.0, 3.0], [0.0, 3.0]]);
    assert_eq!((m("glass").transmission, m("glass").base_color[3]), (0.75, 1.0));
    assert_eq!(mode(m("glass")), AlphaMode::Opaque as u32, "transmission is no longer coverage");
    assert_eq!((m("tinted").transmission, m("tinted").base_color[3]), (0.5, 0.5));
    assert_eq!(mode(m("tinted")), AlphaMode::Blend as u32);
    assert_eq!((m("masked").transmission, mode(m("masked"))), (0.5, AlphaMode::Mask as u32));
    assert_eq!(m("loud").transmission, 1.0);
    assert_eq!((m("none").transmission, m("none").transmission_texture), (0.0, NO_TEXTURE));
    let warned = |text: &str| s.warnings.iter().filter(|w| w.message.contains(text)).count();
    assert_eq!(warned("transmissionFactor"), 1, "{:#?}", s.warnings);
    assert_eq!(warned("coverage"), 0, "{:#?}", s.warnings);
    assert_eq!(warned("used but not supported"), 0, "{:#?}", s.warnings);
}

/// KHR_materials_clearcoat, which the gltf crate does not parse, read from its JSON: factors
/// (clamped into [0, 1] with a warning), both textures (one image in both roles is one data
/// texture) through their KHR_texture_transform; a payload kiln cannot use costs a warning,
/// never the import.
#[test]
fn clear_coats_are_read_and_bad_payloads_only_warned_about() {
    let d = tempfile::tempdir().unwrap();
    write_white_png(d.path());
    let mut g = Gltf::quad();
    let coat = |c: serde_json::Value| json!({ "KHR_materials_clearcoat": c });
    g.textured(
        json!({"name": "paint", "extensions": coat(json!({
            "clearcoatFactor": 0.8,
            "clearcoatRoughnessFactor": 0.2,
            "clearcoatTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [2.0, 3.0]}}},
            "clearcoatRoughnessTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [2.0, 3.0]}}}
        }))}),
        "white.png",
    );
    g.json["extensionsUsed"] = json!(["KHR_materials_clearcoat", "KHR_texture_transform"]);
    let mut materials = g.json["materials"].as_array().unwrap().clone();
    materials.extend([
        json!({"name": "loud", "extensions": coat(json!({"clearcoatFactor": 3.0, "clearcoatRoughnessFactor": -1.0}))}),
        json!({"name": "odd", "extensions": coat(json!({"clearcoatFactor": "shiny"}))}),
        json!({"name": "missing", "extensions": coat(json!({"clearcoatFactor": 1.0, "clearcoatTexture": {"index": 7}}))}),
        json!({"name": "bumpy", "extensions": coat(json!({"clearcoatFactor": 1.0, "clearcoatNormalTexture": {"index": 0}}))}),
        json!({"name": "scalar", "extensions": coat(json!(5))}),
        json!({"name": "bare"}),
    ]);
    g.json["materials"] = json!(materials);
    one_primitive_per_material(&mut g);
    let s = import(&g.write(d.path(), "coat")).unwrap();
    let m = |name: &str| s.materials.iter().find(|m| m.name == name).unwrap().gpu;
    let paint = m("paint");
    assert_eq!((paint.clearcoat, paint.clearcoat_roughness), (0.8, 0.2));
    assert_ne!(paint.clearcoat_texture, NO_TEXTURE);
    assert_eq!(paint.clearcoat_texture, paint.clearcoat_roughness_texture, "one data texture in both slots");
    // The coat's transform is the material's mapping, baked into the coordinates.
    assert_eq!(s.uvs[..4], [[0.0, 0.0], [2.0, 0.0], [2.0, 3.0], [0.0, 3.0]]);
    assert_eq!((m("loud").clearcoat, m("loud").clearcoat_roughness), (1.0, 0.0));
    assert_eq!(m("odd").clearcoat, 0.0);
    assert_eq!((m("missing").clearcoat, m("missing").clearcoat_texture), (1.0, NO_TEXTURE));
    assert_eq!(m("bumpy").clearcoat, 1.0);
    for name in ["scalar", "bare"] {
        assert_eq!((m(name).clearcoat, m(name).clearcoat_texture), (0.0, NO_TEXTURE), "{name}");
    }
    let warned = |text: &str| s.warnings.iter().filter(|w| w.message.contains(text)).count();
    assert_eq!(warned("clamped to"), 2, "{:#?}", s.warnings);
    assert_eq!(warned("\"shiny\", not a number"), 1, "{:#?}", s.warnings);
    assert_eq!(warned("does not name one of the file's 1 textures"), 1, "{:#?}", s.warnings);
    assert_eq!(warned("clearcoatNormalTexture is not applied"), 1, "{:#?}", s.warnings);
    assert_eq!(warned("is not a JSON object"), 1, "{:#?}", s.warnings);
    assert_eq!(warned("used but not supported"), 0, "{:#?}", s.warnings);
}

/// Alpha-blended materials whose alpha is 1 everywhere become opaque; any alpha below 1 — the
/// factor, one texel of the base colour texture, one vertex colour — keeps them blended. Read
/// back from the compiled file's material table. Planted and seen failing: the texture's texels
/// not looked at (the material with one translucent texel made opaque).
#[test]
fn blended_materials_with_alpha_one_everywhere_compile_opaque() {
    use kiln_compiler::import::demo::lambert_material;
    use kiln_compiler::ir::{Material, Texture};
    use kiln_format::sections::{AlphaMode, GpuMaterial, MATERIALS, Vertex};
    use kiln_format::{Checksums, KilnFile};

    let mut s = Scene { name: "blends".into(), ..Default::default() };
    let texture = |alpha_of_one: u8| Texture {
        name: format!("t{alpha_of_one}"),
        width: 2,
        height: 2,
        rgba: vec![200, 200, 200, 255, 200, 200, 200, 255, 200, 200, 200, 255, 200, 200, 200, alpha_of_one],
        role: TextureRole::Color,
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        mag_linear: true,
    };
    s.textures = vec![texture(255), texture(128)];
    // (base colour alpha, texture, a vertex colour alpha below 1) per material.
    let cases: [(f32, u32, bool); 5] = [
        (1.0, 0, false),
        (1.0, 1, false),
        (0.5, NO_TEXTURE, false),
        (1.0, NO_TEXTURE, true),
        (1.0, NO_TEXTURE, false),
    ];
    for (i, &(alpha, tex, vertex_alpha)) in cases.iter().enumerate() {
        let mut g = lambert_material([0.8; 3]);
        g.base_color[3] = alpha;
        g.base_color_texture = tex;
        g.flags |= (AlphaMode::Blend as u32) << MaterialFlags::ALPHA_MODE_SHIFT;
        s.materials.push(Material { name: format!("m{i}"), gpu: g });
        let (x, b) = (i as f32 * 2.0, s.vertices.len() as u32);
        for p in [[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x + 1.0, 1.0, 0.0], [x, 1.0, 0.0]] {
            s.vertices.push(Vertex { position: p, normal: [0.0, 0.0, 1.0] });
            s.uvs.push([p[0] - x, p[1]]);
            s.colors.push([u16::MAX, u16::MAX, u16::MAX, if vertex_alpha { 30000 } else { u16::MAX }]);
        }
        s.triangles.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
        s.triangle_materials.extend([i as u32; 2]);
    }
    let bytes = kiln_compiler::pipeline::compile_to_bytes(s, Default::default(), "test").unwrap();
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let materials: &[GpuMaterial] = file.pod(MATERIALS, 0).unwrap().unwrap();
    let modes: Vec<_> = materials.iter().map(|m| m.alpha_mode()).collect();
    use AlphaMode::{Blend, Opaque};
    assert_eq!(modes, [Some(Opaque), Some(Blend), Some(Blend), Some(Blend), Some(Opaque)]);
}
