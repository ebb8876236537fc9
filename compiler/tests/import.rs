//! Import semantics: transforms, winding, primitive modes, sparse accessors, normals, GLB and
//! data URIs, lights and cameras, OBJ/MTL rules, texture colour spaces and mip chains (the
//! material extensions: `import_materials.rs`).

#[path = "util/gltf.rs"]
mod gltf_builder;

use base64::Engine;
use glam::Vec3;
use gltf_builder::{Gltf, write_white_png};
use kiln_compiler::import::{import, import_with};
use kiln_compiler::ir::{Scene, TextureRole};
use kiln_compiler::settings::Normals;
use kiln_format::manifest::{LightKind, Wrap};
use kiln_format::sections::MaterialFlags;
use serde_json::json;

/// cos 45° = sin 45°, for quaternions of 90° turns.
const H: f32 = std::f32::consts::FRAC_1_SQRT_2;

fn corners(s: &Scene, t: usize) -> [Vec3; 3] {
    s.triangles[t].map(|i| Vec3::from(s.vertices[i as usize].position))
}

fn geometric_normal(s: &Scene, t: usize) -> Vec3 {
    let c = corners(s, t);
    (c[1] - c[0]).cross(c[2] - c[0]).normalize()
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

#[test]
fn node_hierarchy_composes_transforms() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::quad();
    g.json["nodes"] = json!([
        {"translation": [10.0, 0.0, 0.0], "children": [1]},
        {"mesh": 0, "scale": [2.0, 2.0, 2.0], "rotation": [0.0, 0.0, H, H]}
    ]);
    let s = import(&g.write(d.path(), "h")).unwrap();
    // Corner (1, 0, 0): scaled to (2, 0, 0), rotated 90° about z to (0, 2, 0), moved to (10, 2, 0).
    assert!(close(Vec3::from(s.vertices[1].position), Vec3::new(10.0, 2.0, 0.0)), "{:?}", s.vertices[1]);
}

#[test]
fn mirroring_flips_winding() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::quad();
    g.json["nodes"] = json!([{"mesh": 0}, {"mesh": 0, "scale": [-1.0, 1.0, 1.0]}]);
    g.json["scenes"][0]["nodes"] = json!([0, 1]);
    let s = import(&g.write(d.path(), "m")).unwrap();
    assert_eq!(s.triangles.len(), 4);
    for t in 0..4 {
        // The front face keeps facing +z, mirrored or not.
        assert!(close(geometric_normal(&s, t), Vec3::Z), "triangle {t}: {:?}", geometric_normal(&s, t));
        assert!(close(Vec3::from(s.vertices[s.triangles[t][0] as usize].normal), Vec3::Z));
    }
}

#[test]
fn strips_and_fans() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    let p =
        g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 2.0, 0.0]]);
    g.json["meshes"] = json!([{"primitives": [{"attributes": {"POSITION": p}, "mode": 5}, {"attributes": {"POSITION": p}, "mode": 6}]}]);
    let s = import(&g.write(d.path(), "sf")).unwrap();
    assert_eq!(&s.triangles[..3], &[[0, 1, 2], [2, 1, 3], [2, 3, 4]]);
    // The fan's second triangle faces -z, so flat normals give its corners their own vertices:
    // compare corners by position (vertex i of the accessor is at `pos[i]`).
    let pos = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 2.0, 0.0]];
    let fan: Vec<[[f32; 3]; 3]> =
        (3..6).map(|t| s.triangles[t].map(|i| s.vertices[i as usize].position)).collect();
    assert_eq!(fan, [[1, 2, 0], [2, 3, 0], [3, 4, 0]].map(|t: [usize; 3]| t.map(|i| pos[i])));
    for t in 0..3 {
        assert!(close(geometric_normal(&s, t), Vec3::Z), "strip triangle {t} winding");
    }
}

#[test]
fn sparse_accessor_overrides_values() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::quad();
    let idx = g.view(&2u16.to_le_bytes(), None);
    let vals: Vec<u8> = [5.0f32, 6.0, 7.0].iter().flat_map(|v| v.to_le_bytes()).collect();
    let val = g.view(&vals, None);
    g.json["accessors"][0]["sparse"] = json!({"count": 1, "indices": {"bufferView": idx, "componentType": 5123}, "values": {"bufferView": val}});
    let s = import(&g.write(d.path(), "sp")).unwrap();
    assert_eq!(s.vertices[2].position, [5.0, 6.0, 7.0]);
    assert_eq!(s.vertices[1].position, [1.0, 0.0, 0.0]);
}

#[test]
fn smooth_normals_on_request_are_angle_weighted() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    // Vertex 0 is shared by a triangle in z = 0 (corner angle 90°) and one in x = 0 (45°).
    let p =
        g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, -1.0]]);
    let i = g.indices(&[0, 1, 2, 0, 2, 4, 0, 4, 3]);
    g.mesh(json!({"attributes": {"POSITION": p}, "indices": i}));
    // Angle-weighted smoothing is asked for: glTF's own rule is flat.
    let s = import_with(&g.write(d.path(), "n"), Normals::Smooth { crease_degrees: None }).unwrap();
    // Face normals: +z (angle 90° at v0), -x (two triangles, 45° each).
    let expected = (Vec3::Z * 90f32.to_radians() + Vec3::NEG_X * 90f32.to_radians()).normalize();
    assert!(close(Vec3::from(s.vertices[0].normal), expected), "{:?}", s.vertices[0].normal);
}

#[test]
fn glb_and_data_uri_give_the_same_scene_as_gltf() {
    let d = tempfile::tempdir().unwrap();
    let a = import(&Gltf::quad().write(d.path(), "a")).unwrap();
    let b = import(&Gltf::quad().write_glb(d.path(), "b")).unwrap();
    let mut g = Gltf::quad();
    let f = g.write(d.path(), "c");
    let b64 = base64::engine::general_purpose::STANDARD.encode(&g.bin);
    Gltf::set_buffer_uri(&f, &format!("data:application/octet-stream;base64,{b64}"));
    let c = import(&f).unwrap();
    for s in [&b, &c] {
        assert_eq!(s.vertices, a.vertices);
        assert_eq!(s.triangles, a.triangles);
    }
    assert_eq!(c.inputs.len(), 1, "a data URI reads no file");
}

#[test]
fn lights_cameras_and_emissive_strength() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::quad();
    g.json["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_materials_emissive_strength"]);
    g.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"type": "spot", "intensity": 30.0, "color": [1.0, 0.5, 0.25], "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
        {"type": "directional", "intensity": 3.0}
    ]}});
    g.json["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}]);
    g.json["nodes"] = json!([
        {"mesh": 0},
        {"translation": [0.0, 5.0, 0.0], "rotation": [-H, 0.0, 0.0, H], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"translation": [0.0, 0.0, 4.0], "camera": 0}
    ]);
    g.json["scenes"][0]["nodes"] = json!([0, 1, 2, 3]);
    g.json["materials"] = json!([{"emissiveFactor": [1.0, 0.5, 0.0], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}}]);
    g.json["meshes"][0]["primitives"][0]["material"] = 0.into();
    let s = import(&g.write(d.path(), "l")).unwrap();
    assert_eq!(s.lights.len(), 2);
    let spot = &s.lights[0];
    assert!(
        matches!(spot.kind, LightKind::Spot { inner_cone, outer_cone } if inner_cone == 0.2 && outer_cone == 0.5)
    );
    assert!(close(Vec3::from(spot.position), Vec3::new(0.0, 5.0, 0.0)));
    // -z rotated by -90° about x points down.
    assert!(close(Vec3::from(spot.direction), Vec3::NEG_Y), "{:?}", spot.direction);
    assert_eq!((spot.intensity, spot.color), (30.0, [1.0, 0.5, 0.25]));
    assert!(matches!(s.lights[1].kind, LightKind::Directional));
    assert!(close(Vec3::from(s.lights[1].direction), Vec3::NEG_Z));
    let cam = &s.cameras[0];
    assert!(close(Vec3::from(cam.position), Vec3::new(0.0, 0.0, 4.0)));
    assert!(close(Vec3::from(cam.target), Vec3::new(0.0, 0.0, 3.0)));
    assert!((cam.vfov_degrees - 0.5f32.to_degrees()).abs() < 1e-4);
    assert_eq!(s.materials[0].gpu.emission, [4.0, 2.0, 0.0]);
}

/// A bad MTL statement costs that statement, not the library (tobj failed the whole library on
/// McGuire's `sportsCar.mtl`, whose `Ka 0 0 0c` then left every face the default material): the
/// materials before and after it keep what the file gives them, the bad lines are warned about
/// with their line numbers, and texture options are read before a file name with spaces.
#[test]
fn a_bad_mtl_statement_costs_that_statement_only() {
    let d = tempfile::tempdir().unwrap();
    let mtl = "newmtl before\nKd 0.5 0.25 0.125\nKa 0 0 0c\nillum x\n\nnewmtl\nKd 0.3\n\n\
               newmtl after\nKd 0.75 0.5 0.25\nmap_Kd\nmap_Kd -clamp on -o 0.5 0 0 -s 1 1 1 my tex.png\n";
    std::fs::write(d.path().join("m.mtl"), mtl).unwrap();
    image::RgbaImage::from_pixel(4, 4, image::Rgba([255, 255, 255, 255]))
        .save(d.path().join("my tex.png"))
        .unwrap();
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n\
               usemtl before\nf 1/1 2/2 3/3\nusemtl after\nf 1/1 3/3 2/2\n";
    std::fs::write(d.path().join("s.obj"), obj).unwrap();
    let s = import(&d.path().join("s.obj")).unwrap();
    let m = |n: &str| {
        s.materials.iter().find(|m| m.name == n).unwrap_or_else(|| panic!("no {n}: {:?}", s.materials)).gpu
    };
    assert_eq!(&m("before").base_color[..3], &[0.5, 0.25, 0.125]);
    assert_eq!(&m("after").base_color[..3], &[0.75, 0.5, 0.25]);
    // A nameless material is named after its line; `Kd r` is r r r (the MTL specification).
    assert_eq!(&m("unnamed-6").base_color[..3], &[0.3, 0.3, 0.3]);
    // Both faces keep their materials.
    let names: Vec<&str> =
        s.triangle_materials.iter().map(|&i| s.materials[i as usize].name.as_str()).collect();
    assert_eq!(names, ["before", "after"]);
    let warned = |text: &str| s.warnings.iter().any(|w| w.message.contains(text));
    for line in ["m.mtl:3:", "m.mtl:4:", "m.mtl:6:", "m.mtl:11:"] {
        assert!(warned(line), "no warning for {line}: {:#?}", s.warnings);
    }
    // The texture: its name with a space, clamped, its offset warned about.
    let t = &s.textures[m("after").base_color_texture as usize];
    assert_eq!((t.name.as_str(), t.wrap_u, t.wrap_v), ("my tex.png", Wrap::ClampToEdge, Wrap::ClampToEdge));
    assert!(warned("-o 0.5 0 0 (texture offset) is not applied"), "{:#?}", s.warnings);
    assert!(!warned("-s"), "-s 1 1 1 is the default: {:#?}", s.warnings);
}

#[test]
fn obj_mtl_rule() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(
        d.path().join("m.mtl"),
        "newmtl matte\nKd 0.5 0.25 0.125\nKs 0 0 0\n\nnewmtl shiny\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\nNs 98\n\nnewmtl lamp\nKd 0 0 0\nKe 10 9 8\n",
    )
    .unwrap();
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
               o a\nusemtl matte\nf 1/1 2/2 3/3 4/4\no b\nusemtl shiny\nf -4 -3 -2\nusemtl lamp\nf 1 3 4\n";
    std::fs::write(d.path().join("s.obj"), obj).unwrap();
    let s = import(&d.path().join("s.obj")).unwrap();
    let m = |n: &str| s.materials.iter().find(|m| m.name == n).unwrap().gpu;
    let matte = m("matte");
    assert_eq!(matte.flags & MaterialFlags::DIFFUSE_ONLY, MaterialFlags::DIFFUSE_ONLY);
    assert_eq!(&matte.base_color[..3], &[0.5, 0.25, 0.125]);
    assert_eq!(matte.metallic, 0.0);
    let shiny = m("shiny");
    assert_eq!(shiny.flags & MaterialFlags::DIFFUSE_ONLY, 0);
    assert!((shiny.roughness - (2.0f32 / 100.0).powf(0.25)).abs() < 1e-6);
    assert_eq!(m("lamp").emission, [10.0, 9.0, 8.0]);
    // The quad became two triangles, the negative-index face one.
    assert_eq!(s.triangles.len(), 4);
    assert!(s.inputs.iter().any(|p| p.ends_with("m.mtl")));
    // OBJ v runs up; kiln's v runs down.
    let top = s.vertices.iter().position(|v| v.position == [1.0, 1.0, 0.0]).unwrap();
    assert_eq!(s.uvs[top], [1.0, 0.0]);
}

#[test]
fn texture_roles_and_mip_chain_filtering() {
    let d = tempfile::tempdir().unwrap();
    // A 2x2 image: black and white texels; its 1x1 mip is their average in linear light.
    let mut png = Vec::new();
    let img = image::RgbaImage::from_raw(
        2,
        2,
        vec![0, 0, 0, 255, 255, 255, 255, 255, 0, 0, 0, 255, 255, 255, 255, 255],
    )
    .unwrap();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
    std::fs::write(d.path().join("bw.png"), &png).unwrap();
    let mut g = Gltf::quad();
    g.textured(
        json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 0}}}),
        "bw.png",
    );
    let s = import(&g.write(d.path(), "tex")).unwrap();
    // One image used in two roles gives two textures (sRGB and linear).
    assert_eq!(s.textures.len(), 2);
    let color = s.textures.iter().find(|t| t.role == TextureRole::Color).unwrap();
    let data = s.textures.iter().find(|t| t.role == TextureRole::Data).unwrap();
    let chain = kiln_compiler::bake::textures::mip_chain(color);
    assert_eq!(chain.len(), (4 + 1) * 4);
    // Linear average 0.5 → sRGB 0.7354 → 188.
    assert_eq!(&chain[16..20], &[188, 188, 188, 255]);
    let chain = kiln_compiler::bake::textures::mip_chain(data);
    assert_eq!(&chain[16..20], &[128, 128, 128, 255]);
}

#[test]
fn sidecar_lights_keep_their_kinds_and_units() {
    use kiln_compiler::import::sidecar::Sidecar;
    let d = tempfile::tempdir().unwrap();
    let mut s = import(&Gltf::quad().write(d.path(), "q")).unwrap();
    let side = Sidecar::parse(
        r#"
[[light]]
kind = "directional"
direction = [0.0, -2.0, 0.0]
intensity = 3.0

[[light]]
kind = "point"
position = [0.0, 1.9, 0.0]
color = [1.0, 0.9, 0.8]
intensity = 5.0

[[light]]
kind = "spot"
position = [0.0, 3.0, 0.0]
direction = [0.0, -1.0, 0.0]
intensity = 7.0
outer_cone_degrees = 40.0

[[light]]
kind = "rect"
position = [0.0, 2.0, 0.0]
direction = [0.0, -1.0, 0.0]
right = [1.0, 0.0, 0.5]
size = [0.5, 0.25]
intensity = 9.0
"#,
    )
    .unwrap();
    side.apply(&mut s, "test.toml").unwrap();
    let kinds: Vec<String> = s.lights.iter().map(|l| format!("{:?}", l.kind)).collect();
    assert!(matches!(s.lights[0].kind, LightKind::Directional), "{kinds:?}");
    assert_eq!(s.lights[0].direction, [0.0, -1.0, 0.0]);
    assert!(matches!(s.lights[1].kind, LightKind::Point));
    assert_eq!((s.lights[1].color, s.lights[1].intensity), ([1.0, 0.9, 0.8], 5.0));
    assert!(matches!(s.lights[2].kind, LightKind::Spot { inner_cone, outer_cone }
        if (outer_cone - 40f32.to_radians()).abs() < 1e-6 && (inner_cone - 32f32.to_radians()).abs() < 1e-6));
    assert!(matches!(s.lights[3].kind, LightKind::Rect { width, height } if width == 0.5 && height == 0.25));
    // `right` is made orthogonal to the direction and unit length.
    assert!(close(Vec3::from(s.lights[3].right), Vec3::new(1.0, 0.0, 0.5).normalize()));
}

/// Normal stored at corner `k` of triangle `t`.
fn corner_normal(s: &Scene, t: usize, k: usize) -> Vec3 {
    Vec3::from(s.vertices[s.triangles[t][k] as usize].normal)
}

/// A unit cube [0, 1]³ as 8 shared corners (vertex x + 2y + 4z) and 12 triangles, counter-clockwise
/// seen from outside, without normals.
fn cube_gltf() -> Gltf {
    let mut g = Gltf::new();
    let corners: Vec<[f32; 3]> =
        (0..8).map(|v| [(v & 1) as f32, ((v >> 1) & 1) as f32, ((v >> 2) & 1) as f32]).collect();
    let p = g.positions(&corners);
    let quads = [[4, 5, 7, 6], [0, 2, 3, 1], [1, 3, 7, 5], [0, 4, 6, 2], [2, 6, 7, 3], [0, 1, 5, 4]];
    let idx: Vec<u32> = quads.iter().flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect();
    let i = g.indices(&idx);
    g.mesh(json!({"attributes": {"POSITION": p}, "indices": i}));
    g
}

/// The outward normal of a cube triangle, from its corners alone: the axis along which all
/// three share a coordinate, positive where that coordinate is 1.
fn cube_face_axis(c: [Vec3; 3]) -> Vec3 {
    let axis = (0..3).find(|&a| c[0][a] == c[1][a] && c[1][a] == c[2][a]).unwrap();
    let mut n = Vec3::ZERO;
    n[axis] = if c[0][axis] == 1.0 { 1.0 } else { -1.0 };
    n
}

#[test]
fn gltf_without_normals_is_flat() {
    let d = tempfile::tempdir().unwrap();
    let s = import(&cube_gltf().write(d.path(), "cube")).unwrap();
    assert_eq!(s.triangles.len(), 12);
    // Each of the 8 corners is split into one vertex per face that meets there: 24.
    assert_eq!(s.vertices.len(), 24);
    assert_eq!(s.uvs.len(), 24);
    for t in 0..12 {
        let axis = cube_face_axis(corners(&s, t));
        assert_eq!(geometric_normal(&s, t), axis, "winding of triangle {t}");
        for k in 0..3 {
            assert_eq!(corner_normal(&s, t, k), axis, "triangle {t} corner {k}");
        }
    }
}

#[test]
fn crease_angle_on_a_cube_and_a_gentle_strip() {
    let d = tempfile::tempdir().unwrap();
    let cube = cube_gltf().write(d.path(), "cube");
    let smooth = |crease: Option<f32>| Normals::Smooth { crease_degrees: crease };
    // 90° between faces: a 30° crease keeps them flat.
    let s = import_with(&cube, smooth(Some(30.0))).unwrap();
    for t in 0..12 {
        let axis = cube_face_axis(corners(&s, t));
        (0..3).for_each(|k| assert_eq!(corner_normal(&s, t, k), axis, "crease 30: triangle {t} corner {k}"));
    }
    // No crease, or one of 100°: three faces meet at each corner with 90° of corner angle each, so
    // the normal is the corner's diagonal (±1, ±1, ±1)/√3, pointing away from the centre.
    for crease in [None, Some(100.0)] {
        let s = import_with(&cube, smooth(crease)).unwrap();
        assert_eq!(s.vertices.len(), 8, "{crease:?}");
        for v in &s.vertices {
            let diagonal = (Vec3::from(v.position) * 2.0 - Vec3::ONE) / 3f32.sqrt();
            assert!(close(Vec3::from(v.normal), diagonal), "{crease:?}: {v:?}");
        }
    }

    // A strip of 3 rectangles around the unit cylinder about y, columns at φ = 0°, 10°, 20°, 30°
    // (x = sin φ, z = cos φ): 10° between neighbouring faces.
    let mut g = Gltf::new();
    let col = |i: usize| (i as f32 * 10.0).to_radians();
    let pos: Vec<[f32; 3]> = (0..8).map(|v| [col(v / 2).sin(), (v % 2) as f32, col(v / 2).cos()]).collect();
    let p = g.positions(&pos);
    let idx: Vec<u32> =
        (0..3u32).flat_map(|i| [2 * i, 2 * i + 2, 2 * i + 3, 2 * i, 2 * i + 3, 2 * i + 1]).collect();
    let i = g.indices(&idx);
    g.mesh(json!({"attributes": {"POSITION": p}, "indices": i}));
    let strip = g.write(d.path(), "strip");
    let radial = |phi: f32| Vec3::new(phi.sin(), 0.0, phi.cos());
    // Face f (triangles 2f, 2f + 1) faces its middle angle (f + ½)·10°.
    let face = |t: usize| radial(((t / 2) as f32 * 10.0 + 5.0).to_radians());
    // A 30° crease smooths across 10°: inner columns get the mean of two unit normals at ±5°
    // with equal weight (each rectangle has 90° at the vertex), i.e. their own radial direction;
    // edge columns their one face's normal.
    let s = import_with(&strip, smooth(Some(30.0))).unwrap();
    assert_eq!(s.vertices.len(), 8);
    for t in 0..6 {
        assert!(close(geometric_normal(&s, t), face(t)), "strip winding {t}");
        for k in 0..3 {
            let p = Vec3::from(s.vertices[s.triangles[t][k] as usize].position);
            let phi = p.x.atan2(p.z);
            let inner = phi > 0.05 && phi < 30f32.to_radians() - 0.05;
            let expected = if inner { radial(phi) } else { face(t) };
            assert!(close(corner_normal(&s, t, k), expected), "crease 30: triangle {t} corner {k}");
        }
    }
    // A 5° crease does not: every corner its face's normal.
    let s = import_with(&strip, smooth(Some(5.0))).unwrap();
    for t in 0..6 {
        (0..3).for_each(|k| {
            assert!(close(corner_normal(&s, t, k), face(t)), "crease 5: triangle {t} corner {k}")
        });
    }
}

#[test]
fn obj_smoothing_groups() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("m.mtl"), "newmtl red\nKd 1 0 0\n\nnewmtl white\nKd 1 1 1\n").unwrap();
    // C: a pentagon in y = 0 (tobj fans it into 3 triangles) before any `s`: flat.
    // A (z = 0, +z) and B (x = 0, -x) in group 1 share the edge from P0 = (0,0,0) to P3 = (0,1,0)
    // at 90°, after a `usemtl` that starts a new tobj model.
    // D (y = 1) in group 2 shares P3 with A and B, and Q2 = (0,1,-1) with B.
    // E (x = 1) after `s off` shares the edge P1 P2 with A and P2 with D.
    let obj = "mtllib m.mtl\n\
               v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 1 -1\nv 0 0 -1\nv 1 0 -1\nv 0.5 0 0.5\nv 1 1 -1\n\
               o box\nusemtl red\nf 1 6 7 2 8\n\
               usemtl white\ns 1\nf 1 2 3 4\nf 1 4 5 6\n\
               s 2\nf 4 5 9 3\n\
               s off\nf 2 3 7\n";
    std::fs::write(d.path().join("g.obj"), obj).unwrap();
    let s = import(&d.path().join("g.obj")).unwrap();
    assert_eq!(s.triangles.len(), 3 + 2 + 2 + 2 + 1);
    // At P0 and P3, A and B each have 90° of corner angle (45° + 45° at P0; 90° in one triangle
    // at P3): the normal is (+z + -x)/√2.
    let r = 0.5f32.sqrt();
    let ab = Vec3::new(-r, 0.0, r);
    let mut seen = [0; 5];
    for t in 0..s.triangles.len() {
        let c = corners(&s, t);
        let n = geometric_normal(&s, t);
        let on = |axis: usize, v: f32| c.iter().all(|p| p[axis] == v);
        let (name, face) = if on(2, 0.0) {
            ("A", Vec3::Z)
        } else if on(0, 0.0) {
            ("B", Vec3::NEG_X)
        } else if on(1, 0.0) {
            ("C", Vec3::NEG_Y)
        } else if on(1, 1.0) {
            ("D", Vec3::NEG_Y)
        } else {
            ("E", Vec3::NEG_X)
        };
        seen["ABCDE".find(name).unwrap()] += 1;
        assert!(close(n, face), "{name}: winding");
        for (k, p) in c.iter().enumerate() {
            let shared_ab = (name == "A" || name == "B") && p.x == 0.0 && p.z == 0.0;
            let expected = if shared_ab { ab } else { face };
            assert!(
                close(corner_normal(&s, t, k), expected),
                "{name} corner at {p}: {}",
                corner_normal(&s, t, k)
            );
        }
    }
    assert_eq!(seen, [2, 2, 3, 2, 1]);
}

#[test]
fn obj_normals_override_and_given_normals() {
    let d = tempfile::tempdir().unwrap();
    // Two triangles folded at 90° along the edge (0,0,0)-(0,1,0), no `s`: flat by default,
    // smooth on request; with `vn` normals given, those are kept whatever is asked.
    let geometry = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 -1\n";
    std::fs::write(d.path().join("f.obj"), format!("{geometry}f 1 2 3\nf 1 3 4\n")).unwrap();
    std::fs::write(
        d.path().join("n.obj"),
        format!("{geometry}vn 0 0 2\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n"),
    )
    .unwrap();
    let flat = import(&d.path().join("f.obj")).unwrap();
    assert_eq!(flat.vertices.len(), 6);
    let smooth = import_with(&d.path().join("f.obj"), Normals::Smooth { crease_degrees: None }).unwrap();
    assert_eq!(smooth.vertices.len(), 4);
    // At (0,0,0): +z with 90° and -x with 90°.
    let r = 0.5f32.sqrt();
    assert!(close(Vec3::from(smooth.vertices[0].normal), Vec3::new(-r, 0.0, r)));
    for t in 0..2 {
        let face = geometric_normal(&flat, t);
        (0..3).for_each(|k| assert_eq!(corner_normal(&flat, t, k), face));
    }
    for mode in [Normals::Asset, Normals::Flat, Normals::Smooth { crease_degrees: None }] {
        let given = import_with(&d.path().join("n.obj"), mode).unwrap();
        assert!(given.vertices.iter().all(|v| v.normal == [0.0, 0.0, 1.0]), "{mode:?}");
    }
}

#[test]
fn normals_setting_parses_and_refuses() {
    use kiln_compiler::settings::Settings;
    assert_eq!(Normals::parse("flat"), Ok(Normals::Flat));
    assert_eq!(Normals::parse("smooth"), Ok(Normals::Smooth { crease_degrees: None }));
    assert_eq!(Normals::parse("smooth:30"), Ok(Normals::Smooth { crease_degrees: Some(30.0) }));
    assert_eq!(Normals::parse("smooth:12.5").map(Normals::name), Ok("smooth:12.5".to_string()));
    for bad in ["round", "smooth:", "smooth:-1", "smooth:181", "smooth:NaN", "smooth:inf", "flat:30"] {
        let e = Normals::parse(bad).unwrap_err();
        assert!(e.contains("flat, smooth or smooth:ANGLE"), "{bad}: {e}");
    }
    let mut settings = Settings::default();
    let side = kiln_compiler::import::sidecar::Sidecar::parse("[bake]\nnormals = \"smooth:30\"\n").unwrap();
    settings.apply_bake_table(&side.bake).unwrap();
    assert_eq!(settings.normals, Normals::Smooth { crease_degrees: Some(30.0) });
    let side = kiln_compiler::import::sidecar::Sidecar::parse("[bake]\nnormals = \"smooth:200\"\n").unwrap();
    let e = settings.apply_bake_table(&side.bake).unwrap_err();
    assert!(e.starts_with("normals: crease angle '200'"), "{e}");
}

#[test]
fn zero_gltf_normal_takes_the_face_normal() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    // A triangle in y = 0 facing +y; given normals +x, a zero one, +x.
    let p = g.positions(&[[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]);
    let bytes: Vec<u8> = [[1.0f32, 0.0, 0.0], [0.0; 3], [1.0, 0.0, 0.0]]
        .iter()
        .flatten()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    let v = g.view(&bytes, None);
    let n = g.accessor(Some(v), 5126, 3, "VEC3", json!({}));
    g.mesh(json!({"attributes": {"POSITION": p, "NORMAL": n}}));
    let s = import(&g.write(d.path(), "z")).unwrap();
    assert_eq!(geometric_normal(&s, 0), Vec3::Y);
    assert_eq!([0, 1, 2].map(|k| corner_normal(&s, 0, k)), [Vec3::X, Vec3::Y, Vec3::X]);
    assert!(
        s.warnings.iter().any(|w| w.message.contains("1 NORMAL values are zero or not finite")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn obj_mtl_specular_colour_and_mirrors() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(
        d.path().join("m.mtl"),
        "newmtl box\nKd 0 0 0\nKs 0.725 0.71 0.68\nNs 200\n\n\
         newmtl mirror\nillum 3\nKd 0.1 0.1 0.1\nKs 0.9 0.8 0.7\n\n\
         newmtl glossy\nillum 5\nKd 0.8 0.6 0.4\nKs 0.2 0.2 0.2\nNs 14\n\n\
         newmtl matte\nKd 0.5 0.5 0.5\nKs 0 0 0\nillum 3\n\n\
         newmtl chrome\nillum 5\nKd 0.3 0.3 0.3\nKs 0.6 0.6 0.65\nNs 1998\n",
    )
    .unwrap();
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl box\nf 1 2 3\nusemtl mirror\nf 1 2 3\n\
               usemtl glossy\nf 1 2 3\nusemtl matte\nf 1 2 3\nusemtl chrome\nf 1 2 3\n";
    std::fs::write(d.path().join("s.obj"), obj).unwrap();
    let s = import(&d.path().join("s.obj")).unwrap();
    let m = |n: &str| s.materials.iter().find(|m| m.name == n).unwrap().gpu;
    let warned = |n: &str, what: &str| {
        s.warnings.iter().any(|w| w.message.contains(&format!("material '{n}'")) && w.message.contains(what))
    };
    // The Cornell box's boxes: black Kd, bright Ks → a metal of colour Ks; roughness
    // (2/202)^¼ = 0.315442 (computed by hand), no information lost (Kd was black).
    let b = m("box");
    assert_eq!(b.base_color, [0.725, 0.71, 0.68, 1.0]);
    assert_eq!(b.metallic, 1.0);
    assert!((b.roughness - 0.315_442).abs() < 1e-6, "{}", b.roughness);
    assert_eq!(b.flags & MaterialFlags::DIFFUSE_ONLY, 0);
    assert!(!s.warnings.iter().any(|w| w.message.contains("'box'")), "{:?}", s.warnings);
    // illum 3 with Ks brighter than Kd and no Ns: a perfect mirror of colour Ks; Kd 0.1 dropped.
    let r = m("mirror");
    assert_eq!((r.base_color, r.metallic, r.roughness), ([0.9, 0.8, 0.7, 1.0], 1.0, 0.0));
    assert!(warned("mirror", "Kd [0.1, 0.1, 0.1] is dropped"), "{:?}", s.warnings);
    // illum 5 but Kd dominates: a dielectric of base colour Kd, roughness (2/16)^¼; Ks only
    // makes the lobe exist, as for most OBJ materials, so no warning (--strict must pass them).
    let g = m("glossy");
    assert_eq!((g.base_color, g.metallic), ([0.8, 0.6, 0.4, 1.0], 0.0));
    assert!((g.roughness - 0.125f32.powf(0.25)).abs() < 1e-6);
    assert!(!s.warnings.iter().any(|w| w.message.contains("'glossy'")), "{:?}", s.warnings);
    // illum 5 (Fresnel reflection) with Ks brighter than Kd: a metal of colour Ks, roughness
    // (2/2000)^¼ = 0.177828 by hand; Kd 0.3 dropped with a warning.
    let c = m("chrome");
    assert_eq!((c.base_color, c.metallic), ([0.6, 0.6, 0.65, 1.0], 1.0));
    assert!((c.roughness - 0.177_828).abs() < 1e-6, "{}", c.roughness);
    assert!(warned("chrome", "Kd [0.3, 0.3, 0.3] is dropped"), "{:?}", s.warnings);
    // Ks 0 stays pure Lambertian whatever illum says.
    let t = m("matte");
    assert_eq!(
        (t.base_color, t.metallic, t.flags & MaterialFlags::DIFFUSE_ONLY),
        ([0.5, 0.5, 0.5, 1.0], 0.0, MaterialFlags::DIFFUSE_ONLY)
    );
    assert!(!s.warnings.iter().any(|w| w.message.contains("'matte'")), "{:?}", s.warnings);
}

/// The quad with one morph target lifting corners 2 and 3 by 1 along z.
fn morphed_quad() -> Gltf {
    let mut g = Gltf::quad();
    let deltas: Vec<u8> = [[0.0f32, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let v = g.view(&deltas, None);
    let a = g.accessor(Some(v), 5126, 4, "VEC3", json!({"min": [0.0, 0.0, 0.0], "max": [0.0, 0.0, 1.0]}));
    g.json["meshes"][0]["primitives"][0]["targets"] = json!([{"POSITION": a}]);
    g
}

#[test]
fn morph_targets_apply_at_the_default_weights_node_over_mesh() {
    let d = tempfile::tempdir().unwrap();
    // The mesh's weight 0.25; no node weights: corners 2 and 3 at z = 0.25, the others unmoved.
    let mut g = morphed_quad();
    g.json["meshes"][0]["weights"] = json!([0.25]);
    let s = import(&g.write(d.path(), "morph-mesh")).unwrap();
    assert_eq!(s.vertices[2].position, [1.0, 1.0, 0.25]);
    assert_eq!(s.vertices[3].position, [0.0, 1.0, 0.25]);
    assert_eq!(s.vertices[1].position, [1.0, 0.0, 0.0]);
    // The node's weights win over the mesh's.
    g.json["nodes"][0]["weights"] = json!([1.0]);
    let s = import(&g.write(d.path(), "morph-node")).unwrap();
    assert_eq!(s.vertices[2].position, [1.0, 1.0, 1.0]);
    // No weights anywhere: 0, the base shape.
    let mut g = morphed_quad();
    let s = import(&g.write(d.path(), "morph-none")).unwrap();
    assert_eq!(s.vertices[2].position, [1.0, 1.0, 0.0]);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn animations_and_skins_are_warned_about_never_fatal() {
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::quad();
    let times: Vec<u8> = [0.0f32, 1.0].iter().flat_map(|v| v.to_le_bytes()).collect();
    let tv = g.view(&times, None);
    let input = g.accessor(Some(tv), 5126, 2, "SCALAR", json!({"min": [0.0], "max": [1.0]}));
    let output = g.positions(&[[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]]);
    g.json["animations"] = json!([{
        "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
        "samplers": [{"input": input, "output": output}]
    }]);
    g.json["nodes"] = json!([{"mesh": 0, "skin": 0}, {}]);
    g.json["skins"] = json!([{"joints": [1]}]);
    let s = import(&g.write(d.path(), "anim")).unwrap();
    // Compiled at the rest transform: the animation's 5-unit move is not applied.
    assert_eq!(s.vertices[1].position, [1.0, 0.0, 0.0]);
    let text: Vec<&str> = s.warnings.iter().map(|w| w.message.as_str()).collect();
    assert!(text.iter().any(|w| w.contains("1 animation(s) not baked")), "{text:?}");
    assert!(text.iter().any(|w| w.contains("skinned but it has no JOINTS_0")), "{text:?}");
}

/// Little-endian bytes of `values`.
fn le<T: Copy, const N: usize>(values: &[[T; N]], bytes: impl Fn(T) -> Vec<u8>) -> Vec<u8> {
    values.iter().flatten().flat_map(|&v| bytes(v)).collect()
}

#[test]
fn skinned_meshes_are_posed_as_their_joint_nodes_stand() {
    // Two joints as in Khronos's SimpleSkin: joint A at the origin, joint B one unit up, bound
    // there (inverse bind: down one unit) but standing turned 90° about z in the nodes. A vertex
    // bound to B at (0, 2, 0) swings to (−1, 1, 0); one bound to A stays; one half-and-half lands
    // midway. The skinned node's own translation (10, 0, 0) is ignored, as glTF requires.
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::new();
    let p = g.positions(&[[0.5, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 2.0, 0.0]]);
    let i = g.indices(&[0, 1, 2]);
    let jv = g.view(&le(&[[0u16, 1, 0, 0]; 3], |v: u16| v.to_le_bytes().to_vec()), None);
    let joints = g.accessor(Some(jv), 5123, 3, "VEC4", json!({}));
    // The third vertex's weights sum to 2 (glTF requires 1): normalised, it lands midway all the same.
    let weights = [[1.0f32, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.0]];
    let wv = g.view(&le(&weights, |v: f32| v.to_le_bytes().to_vec()), None);
    let weights = g.accessor(Some(wv), 5126, 3, "VEC4", json!({}));
    let identity = [1.0f32, 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.];
    let mut down = identity;
    down[13] = -1.0; // column-major: translation (0, −1, 0)
    let mv = g.view(&le(&[identity, down], |v: f32| v.to_le_bytes().to_vec()), None);
    let ibm = g.accessor(Some(mv), 5126, 2, "MAT4", json!({}));
    g.mesh(json!({"attributes": {"POSITION": p, "JOINTS_0": joints, "WEIGHTS_0": weights}, "indices": i}));
    g.json["scenes"] = json!([{"nodes": [0, 1]}]);
    g.json["nodes"] = json!([
        {"mesh": 0, "skin": 0, "translation": [10.0, 0.0, 0.0]},
        {"children": [2]},
        {"translation": [0.0, 1.0, 0.0], "rotation": [0.0, 0.0, H, H]}
    ]);
    g.json["skins"] = json!([{"inverseBindMatrices": ibm, "joints": [1, 2]}]);
    let s = import(&g.write(d.path(), "skin")).unwrap();
    let got: Vec<Vec3> = s.vertices.iter().map(|v| Vec3::from(v.position)).collect();
    for want in [Vec3::new(0.5, 0.0, 0.0), Vec3::new(-1.0, 1.0, 0.0), Vec3::new(-0.5, 1.5, 0.0)] {
        assert!(got.iter().any(|&g| close(g, want)), "{want} not among {got:?}");
    }
    // No animation in the file: nothing is lost, so nothing is said.
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

/// The quad with base-colour texture coordinates in sets 0 and 1 and a material whose base
/// colour texture reads `tex_coord`, with `transform` (a `KHR_texture_transform` object) if given.
fn two_uv_sets(tex_coord: u32, transform: Option<serde_json::Value>) -> Gltf {
    let mut g = Gltf::quad();
    g.textured(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}), "white.png");
    let uv1: Vec<u8> = [[0.5f32, 0.25], [0.75, 0.25], [0.75, 0.5], [0.5, 0.5]]
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let v = g.view(&uv1, None);
    let a = g.accessor(Some(v), 5126, 4, "VEC2", json!({}));
    g.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = a.into();
    let info = &mut g.json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"];
    info["texCoord"] = tex_coord.into();
    if let Some(t) = transform {
        info["extensions"] = json!({ "KHR_texture_transform": t });
        g.json["extensionsUsed"] = json!(["KHR_texture_transform"]);
    }
    g
}

#[test]
fn texcoord_set_1_is_read_when_the_material_samples_it() {
    let d = tempfile::tempdir().unwrap();
    write_white_png(d.path());
    let s = import(&two_uv_sets(1, None).write(d.path(), "set1")).unwrap();
    assert_eq!(s.uvs[..4], [[0.5, 0.25], [0.75, 0.25], [0.75, 0.5], [0.5, 0.5]]);
    let s = import(&two_uv_sets(0, None).write(d.path(), "set0")).unwrap();
    assert_eq!(s.uvs[..4], [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn texture_transforms_are_baked_into_the_coordinates() {
    let d = tempfile::tempdir().unwrap();
    write_white_png(d.path());
    // The extension's matrix, translation · rotation · scale, applied by hand: with rotation
    // π/2 (cos 0, sin 1), scale (2, 3), offset (0.5, 0): u' = -3 v + 0.5, v' = 2 u.
    let t = json!({"offset": [0.5, 0.0], "rotation": std::f32::consts::FRAC_PI_2, "scale": [2.0, 3.0]});
    let s = import(&two_uv_sets(0, Some(t)).write(d.path(), "tt")).unwrap();
    let want = [[0.5f32, 0.0], [0.5, 2.0], [-2.5, 2.0], [-2.5, 0.0]];
    for (got, want) in s.uvs.iter().zip(want) {
        assert!((got[0] - want[0]).abs() < 1e-6 && (got[1] - want[1]).abs() < 1e-6, "{got:?} vs {want:?}");
    }
    // The extension's texCoord overrides the reference's.
    let t = json!({"texCoord": 1, "offset": [1.0, 0.0]});
    let s = import(&two_uv_sets(0, Some(t)).write(d.path(), "tt1")).unwrap();
    assert_eq!(s.uvs[0], [1.5, 0.25]);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn a_malformed_animation_is_dropped_with_a_warning_other_errors_still_fail() {
    let d = tempfile::tempdir().unwrap();
    // A channel naming a sampler that does not exist, and an output accessor that does not.
    let mut g = Gltf::quad();
    g.json["animations"] = json!([{
        "channels": [{"sampler": 3, "target": {"node": 0, "path": "translation"}}],
        "samplers": [{"input": 0, "output": 99}]
    }]);
    let s = import(&g.write(d.path(), "bad-anim")).unwrap();
    assert_eq!(s.triangles.len(), 2);
    let text: Vec<&str> = s.warnings.iter().map(|w| w.message.as_str()).collect();
    assert!(
        text.iter().any(|w| w.contains("1 animation(s) dropped unread, as they are malformed")),
        "{text:?}"
    );
    assert!(text.iter().any(|w| w.contains("animations[0]")), "{text:?}");
    // The same fault outside the animations is an error.
    g.json["animations"] = json!([]);
    g.json["meshes"][0]["primitives"][0]["indices"] = json!(99);
    let err = import(&g.write(d.path(), "bad-mesh")).unwrap_err();
    assert!(err.to_string().contains("invalid glTF"), "{err}");
}

#[test]
fn flattened_instances_are_a_performance_warning() {
    // One quad (2 triangles) placed by three nodes: 6 stored triangles, 4 of them copies.
    let d = tempfile::tempdir().unwrap();
    let mut g = Gltf::quad();
    g.json["scenes"] = json!([{"nodes": [0, 1, 2]}]);
    g.json["nodes"] = json!([
        {"mesh": 0},
        {"mesh": 0, "translation": [2.0, 0.0, 0.0]},
        {"mesh": 0, "translation": [4.0, 0.0, 0.0]}
    ]);
    let s = import(&g.write(d.path(), "instances")).unwrap();
    assert_eq!(s.triangles.len(), 6);
    let perf: Vec<&str> = s
        .warnings
        .iter()
        .filter(|w| w.class == kiln_compiler::ir::WarningClass::Performance)
        .map(|w| w.message.as_str())
        .collect();
    assert_eq!(perf.len(), 1, "{:?}", s.warnings);
    assert!(
        perf[0].contains("1 mesh(es)") && perf[0].contains("4 of the scene's 6 triangles (67%)"),
        "{perf:?}"
    );
    // Placed once: no warning.
    let s = import(&Gltf::quad().write(d.path(), "single")).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

/// A scene far from the origin for its size keeps the precision it has at the origin: positions
/// are stored relative to an origin near it (`Scene::origin`), so that stored + origin is the
/// world position to single precision *of the offset from the origin*, not of the world value
/// (floats 10⁵ out are 8 mm apart). Checked for glTF (node translations), OBJ (`v` digits) and
/// the sidecar's camera and light, against world positions computed here in double precision.
#[test]
fn far_scenes_keep_their_precision_relative_to_a_stored_origin() {
    let d = tempfile::tempdir().unwrap();
    // f32 parses of the translation, as glTF's JSON holds single-precision transforms.
    let t = [100000.3f32, -200000.0, 7.25].map(f64::from);
    let mut g = Gltf::quad();
    g.json["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}]);
    g.json["nodes"] = json!([
        {"mesh": 0, "translation": [100000.3, -200000.0, 7.25]},
        {"translation": [100000.8, -199999.5, 9.25], "camera": 0}
    ]);
    g.json["scenes"][0]["nodes"] = json!([0, 1]);
    let s = import(&g.write(d.path(), "far")).unwrap();
    assert_ne!(s.origin, [0.0; 3], "a quad 10⁵ units out is stored relative to an origin near it");
    let world = |p: [f32; 3]| std::array::from_fn::<f64, 3, _>(|a| f64::from(p[a]) + s.origin[a]);
    let quad = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let mut found = 0;
    for v in &s.vertices {
        let w = world(v.position);
        if let Some(q) = quad.iter().find(|q| (0..3).all(|a| (w[a] - (q[a] + t[a])).abs() < 1e-3)) {
            found += 1;
            for a in 0..3 {
                assert!((w[a] - (q[a] + t[a])).abs() <= 1e-6, "vertex {w:?} for corner {q:?} + {t:?}");
            }
        }
    }
    assert_eq!(found, s.vertices.len(), "every vertex is a corner of the moved quad");
    let cam = &s.cameras[0];
    let eye = world(cam.position);
    let expected = [100000.8f32, -199999.5, 9.25].map(f64::from);
    assert!((0..3).all(|a| (eye[a] - expected[a]).abs() <= 1e-6), "camera at {eye:?}");
    // The view direction (−z) survives to single precision.
    let fwd = Vec3::from(cam.target) - Vec3::from(cam.position);
    assert!((fwd - Vec3::NEG_Z).length() < 1e-6, "camera looks along {fwd:?}");

    // OBJ: the file's digits, and a sidecar camera and light in world space.
    let obj = "v 250000.125 3.5 -90000.75\nv 250001.125 3.5 -90000.75\nv 250000.125 4.5 -90000.75\nf 1 2 3\n";
    std::fs::write(d.path().join("far.obj"), obj).unwrap();
    let mut s = import(&d.path().join("far.obj")).unwrap();
    assert_ne!(s.origin, [0.0; 3]);
    let sidecar = kiln_compiler::import::sidecar::Sidecar::parse(
        "[camera]\nposition = [250000.5, 4.0, -89990.75]\ntarget = [250000.5, 4.0, -90000.75]\n\
         [[light]]\nkind = \"point\"\nposition = [250000.625, 5.0, -89999.75]\nintensity = 1.0\n",
    )
    .unwrap();
    sidecar.apply(&mut s, "far.toml").unwrap();
    let world = |p: [f32; 3]| std::array::from_fn::<f64, 3, _>(|a| f64::from(p[a]) + s.origin[a]);
    let v = world(
        s.vertices
            .iter()
            .map(|v| v.position)
            .fold([f32::MAX; 3], |m, p| [m[0].min(p[0]), m[1].min(p[1]), m[2].min(p[2])]),
    );
    assert_eq!(v, [250000.125, 3.5, -90000.75], "the OBJ's smallest corner");
    assert_eq!(world(s.cameras[0].position), [250000.5, 4.0, -89990.75]);
    assert_eq!(world(s.cameras[0].target), [250000.5, 4.0, -90000.75]);
    assert_eq!(world(s.lights[0].position), [250000.625, 5.0, -89999.75]);
}
