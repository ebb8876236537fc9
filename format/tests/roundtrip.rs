//! Round trips: write → read → equal, and re-write → byte-identical, for random contents.

mod common;

use kiln_format::manifest::*;
use kiln_format::sections::{self, CwbvhNode, GpuMaterial, Vertex};
use kiln_format::{Checksums, ContentHash, FileWriter, KilnFile, SectionKind};
use proptest::prelude::*;

fn f32s<const N: usize>() -> impl Strategy<Value = [f32; N]> {
    proptest::array::uniform(proptest::num::f32::ANY)
}

fn text() -> impl Strategy<Value = String> {
    "\\PC{0,12}"
}

fn light() -> impl Strategy<Value = Light> {
    let kind = prop_oneof![
        Just(LightKind::Point),
        Just(LightKind::Directional),
        (any::<f32>(), any::<f32>()).prop_map(|(a, b)| LightKind::Spot { inner_cone: a, outer_cone: b }),
        (any::<f32>(), any::<f32>()).prop_map(|(w, h)| LightKind::Rect { width: w, height: h }),
    ];
    (text(), kind, f32s::<3>(), f32s::<3>(), f32s::<3>(), f32s::<3>(), any::<f32>(), any::<bool>()).prop_map(
        |(name, kind, position, direction, right, color, intensity, casts_shadows)| Light {
            name,
            kind,
            position,
            direction,
            right,
            color,
            intensity,
            range: 0.0,
            casts_shadows,
        },
    )
}

fn texture_info() -> impl Strategy<Value = TextureInfo> {
    (text(), 1u32..5000, 1u32..5000, any::<bool>(), any::<bool>()).prop_map(|(name, w, h, srgb, lin)| {
        TextureInfo {
            name,
            width: w,
            height: h,
            mip_levels: 32 - w.max(h).leading_zeros(),
            color_space: if srgb { ColorSpace::Srgb } else { ColorSpace::Linear },
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::MirroredRepeat,
            mag_linear: lin,
        }
    })
}

fn manifest() -> impl Strategy<Value = Manifest> {
    (
        text(),
        text(),
        prop::collection::vec((text(), any::<u64>(), text()), 0..4),
        prop::collection::vec(light(), 0..4),
        prop::collection::vec(texture_info(), 0..4),
        prop::collection::vec(text(), 0..4),
        (f32s::<3>(), f32s::<3>(), f32s::<3>(), any::<f32>()),
        any::<u64>(),
    )
        .prop_map(|(generator, scene_name, inputs, lights, textures, mats, cam, degenerate)| Manifest {
            generator,
            scene_name,
            inputs: inputs.into_iter().map(|(path, bytes, hash)| InputFile { path, bytes, hash }).collect(),
            settings: vec![Setting { key: "bvh-preset".into(), value: "medium".into() }],
            bounds: Bounds { min: cam.0, max: cam.1 },
            materials: mats.into_iter().map(|name| MaterialInfo { name }).collect(),
            textures,
            lights,
            cameras: vec![Camera {
                name: "c".into(),
                position: cam.0,
                target: cam.1,
                up: cam.2,
                vfov_degrees: cam.3,
                znear: 0.1,
                zfar: 0.0,
            }],
            sky: Sky { radiance: cam.2 },
            media: vec![Medium { bounds: Bounds::default(), sigma_a: cam.0, sigma_s: cam.1, g: cam.3 }],
            skipped: vec![SkippedStage { stage: "shadow-maps".into(), reason: "no lights".into() }],
            degenerate_triangles: degenerate,
            brdf_lut: Some(BrdfLutInfo { resolution: 128, samples: 4096 }),
            shadow_maps: vec![ShadowMapInfo {
                light: 1,
                projection: ShadowProjection::Cube,
                resolution: 512,
                view_proj: [cam.3; 16],
                origin: cam.0,
                direction: cam.1,
                near: 0.0,
                far: cam.3,
                texel: 0.5,
            }],
            media_visibility: Some(MediaVisibilityInfo {
                medium: 0,
                dims: [4, 5, 6],
                samples: 8,
                lights: vec![0, 2],
            }),
            orthographic: vec![OrthographicCamera { camera: 0, xmag: cam.3, ymag: cam.2[0] }],
            origin: cam.1.map(|v| f64::from(v) * 1.0e5),
        })
}

/// Bitwise equality (NaN payloads included), which is what "round trip" means for a file.
fn same_bits<T: bytemuck::Pod>(a: &[T], b: &[T]) -> bool {
    bytemuck::cast_slice::<T, u8>(a) == bytemuck::cast_slice::<T, u8>(b)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn manifest_round_trips(m in manifest()) {
        let bytes = FileWriter::new().manifest(&m, ContentHash::of(b"x")).unwrap().to_bytes().unwrap();
        let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
        let back = file.manifest().unwrap();
        // Compare encodings: f32 NaNs are not equal to themselves, their bytes are.
        prop_assert_eq!(back.encode(), m.encode());
        let again = FileWriter::new().manifest(&back, ContentHash::of(b"x")).unwrap().to_bytes().unwrap();
        prop_assert_eq!(again, bytes);
    }

    #[test]
    fn every_pod_section_round_trips(
        nv in 0usize..50, nt in 0usize..50, nm in 0usize..8, nb in 0usize..8, ntex in 0usize..4,
        seed in any::<u64>(), hash in any::<[u8; 16]>(),
    ) {
        let mut state = seed;
        let mut gen_bytes = |n: usize| -> Vec<u8> { (0..n).map(|_| splitmix(&mut state)).collect() };
        let vertices: Vec<Vertex> = bytemuck::pod_collect_to_vec(&gen_bytes(nv * 24));
        let uvs: Vec<[f32; 2]> = bytemuck::pod_collect_to_vec(&gen_bytes(nv * 8));
        let triangles: Vec<[u32; 3]> = bytemuck::pod_collect_to_vec(&gen_bytes(nt * 12));
        let tmat: Vec<u32> = bytemuck::pod_collect_to_vec(&gen_bytes(nt * 4));
        let mats: Vec<GpuMaterial> = bytemuck::pod_collect_to_vec(&gen_bytes(nm * 80));
        let nodes: Vec<CwbvhNode> = bytemuck::pod_collect_to_vec(&gen_bytes(nb * 80));
        let textures: Vec<Vec<u8>> = (0..ntex).map(|i| gen_bytes(4 * (i + 1) * 7)).collect();
        let h = ContentHash(hash);
        let m = Manifest::default();
        let write = |order: bool| {
            let mut w = FileWriter::new();
            if order {
                w.manifest(&m, h).unwrap();
                w.pod(sections::VERTICES, 0, &vertices, h).unwrap();
                w.pod(sections::UVS, 0, &uvs, h).unwrap();
                w.pod(sections::TRIANGLES, 0, &triangles, h).unwrap();
                w.pod(sections::TRIANGLE_MATERIALS, 0, &tmat, h).unwrap();
                w.pod(sections::MATERIALS, 0, &mats, h).unwrap();
                w.pod(sections::BVH_NODES, 0, &nodes, h).unwrap();
                for (i, t) in textures.iter().enumerate() {
                    w.bytes(sections::TEXTURE, i as u32, t.as_slice(), h).unwrap();
                }
            } else {
                for (i, t) in textures.iter().enumerate().rev() {
                    w.bytes(sections::TEXTURE, i as u32, t.as_slice(), h).unwrap();
                }
                w.pod(sections::BVH_NODES, 0, &nodes, h).unwrap();
                w.pod(sections::MATERIALS, 0, &mats, h).unwrap();
                w.pod(sections::TRIANGLE_MATERIALS, 0, &tmat, h).unwrap();
                w.pod(sections::TRIANGLES, 0, &triangles, h).unwrap();
                w.pod(sections::UVS, 0, &uvs, h).unwrap();
                w.pod(sections::VERTICES, 0, &vertices, h).unwrap();
                w.manifest(&m, h).unwrap();
            }
            w.to_bytes().unwrap()
        };
        let bytes = write(true);
        prop_assert_eq!(&bytes, &write(false), "layout depends on insertion order");
        let f = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
        prop_assert!(same_bits(f.pod::<Vertex>(sections::VERTICES, 0).unwrap().unwrap(), &vertices));
        prop_assert!(same_bits(f.pod::<[f32; 2]>(sections::UVS, 0).unwrap().unwrap(), &uvs));
        prop_assert!(same_bits(f.pod::<[u32; 3]>(sections::TRIANGLES, 0).unwrap().unwrap(), &triangles));
        prop_assert!(same_bits(f.pod::<u32>(sections::TRIANGLE_MATERIALS, 0).unwrap().unwrap(), &tmat));
        prop_assert!(same_bits(f.pod::<GpuMaterial>(sections::MATERIALS, 0).unwrap().unwrap(), &mats));
        prop_assert!(same_bits(f.pod::<CwbvhNode>(sections::BVH_NODES, 0).unwrap().unwrap(), &nodes));
        for (i, t) in textures.iter().enumerate() {
            let s = *f.find(sections::TEXTURE, i as u32).unwrap();
            prop_assert_eq!(&*f.section_bytes(&s).unwrap(), t.as_slice());
            prop_assert_eq!(s.entry.content_hash, h);
        }
        for s in f.sections() {
            prop_assert_eq!(s.entry.offset % 64, 0);
        }
    }
}

/// SplitMix64: a seeded byte source for random section contents.
fn splitmix(state: &mut u64) -> u8 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    (z ^ (z >> 31)) as u8
}

#[test]
fn unknown_sections_are_skipped_and_reported() {
    let m = Manifest { scene_name: "s".into(), ..Default::default() };
    let future = SectionKind(*b"ZZZZ");
    let mut w = FileWriter::new();
    w.manifest(&m, ContentHash::default()).unwrap();
    w.raw(future, 3, 1, vec![7u8; 10], ContentHash::default()).unwrap();
    // A known kind at a newer layout version is skipped too.
    w.raw(sections::VERTICES, 0, 99, vec![1u8; 7], ContentHash::default()).unwrap();
    let bytes = w.to_bytes().unwrap();
    let f = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let skipped: Vec<_> = f.skipped().map(|s| (s.entry.kind, s.entry.index)).collect();
    assert_eq!(skipped, vec![(sections::VERTICES, 0), (future, 3)]);
    assert!(f.pod::<Vertex>(sections::VERTICES, 0).unwrap().is_none());
    assert_eq!(f.manifest().unwrap(), m);
}

#[test]
fn newer_manifest_version_reads_its_known_prefix() {
    let m = Manifest { scene_name: "future".into(), ..Default::default() };
    let mut body = m.encode();
    body.extend_from_slice(b"fields of a later manifest version");
    let mut w = FileWriter::new();
    w.raw(sections::MANIFEST, 0, MANIFEST_VERSION + 1, body.clone(), ContentHash::default()).unwrap();
    let f = KilnFile::from_bytes(&w.to_bytes().unwrap(), Checksums::Eager).unwrap();
    assert_eq!(f.manifest().unwrap(), m);
    // The same trailing bytes at the current version are damage.
    let mut w = FileWriter::new();
    w.raw(sections::MANIFEST, 0, MANIFEST_VERSION, body, ContentHash::default()).unwrap();
    let f = KilnFile::from_bytes(&w.to_bytes().unwrap(), Checksums::Eager).unwrap();
    assert!(f.manifest().unwrap_err().to_string().contains("trailing"));
}

#[test]
fn atomic_write_replaces_and_leaves_no_temp_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.kiln");
    std::fs::write(&path, b"old").unwrap();
    let bytes = common::small_file();
    let f = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let m = f.manifest().unwrap();
    let mut w = FileWriter::new();
    w.manifest(&m, ContentHash::default()).unwrap();
    w.write_atomic(&path).unwrap();
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names.len(), 1, "{names:?}");
    let back = KilnFile::open(&path, Checksums::Eager).unwrap();
    assert_eq!(back.manifest().unwrap(), m);
}

#[test]
fn failed_atomic_write_keeps_the_old_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.kiln");
    std::fs::write(&path, b"old").unwrap();
    // No manifest: the writer refuses before touching the target.
    let mut w = FileWriter::new();
    w.raw(SectionKind(*b"ZZZZ"), 0, 1, vec![1u8], ContentHash::default()).unwrap();
    assert!(w.write_atomic(&path).is_err());
    assert_eq!(std::fs::read(&path).unwrap(), b"old");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1);
}

#[test]
fn version_1_materials_read_as_materials_without_a_coat() {
    // A material as formats 1.0 to 1.7 stored it: 80 bytes, written field by field here
    // (FORMAT.md's `MATL` table): base colour, emission, metallic, roughness, alpha cutoff,
    // normal scale, occlusion strength, five texture numbers, flags, the dielectric's halves.
    let mut v1 = Vec::new();
    let floats = [0.8f32, 0.5, 0.25, 1.0, 2.0, 3.0, 4.0, 0.0, 0.7, 0.5, 1.0, 0.9];
    for f in floats {
        v1.extend(f.to_le_bytes());
    }
    for u in [0u32, u32::MAX, u32::MAX, u32::MAX, u32::MAX, 1, 0, 0] {
        v1.extend(u.to_le_bytes());
    }
    assert_eq!(v1.len(), 80);
    let bytes = common::small_file_with_materials(1, &v1);
    let f = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = kiln_format::scene::SceneView::new(&f).unwrap();
    let m = &view.materials[0];
    assert_eq!(m.base_color, [0.8, 0.5, 0.25, 1.0]);
    assert_eq!(m.emission, [2.0, 3.0, 4.0]);
    assert_eq!((m.metallic, m.roughness, m.alpha_cutoff), (0.0, 0.7, 0.5));
    assert_eq!((m.normal_scale, m.occlusion_strength), (1.0, 0.9));
    assert_eq!(m.base_color_texture, 0);
    assert_eq!(m.flags, 1);
    assert_eq!(m.specular, [0, 0]);
    // No coat, and no coat textures (not texture 0, which zeroed words would name).
    assert_eq!((m.clearcoat, m.clearcoat_roughness), (0.0, 0.0));
    assert_eq!((m.clearcoat_texture, m.clearcoat_roughness_texture), (u32::MAX, u32::MAX));
    assert_eq!((m.transmission, m.transmission_texture, m.reserved), (0.0, u32::MAX, [0, 0]));

    // 80 bytes are not a whole version-2 record: refused, not written as a torn material.
    let mut w = FileWriter::new();
    let err = w.raw(sections::MATERIALS, 0, 2, &v1[..], ContentHash::of(b"m")).unwrap_err();
    assert!(err.to_string().contains("96"), "{err}");
}

#[test]
fn version_2_materials_read_as_materials_that_transmit_nothing() {
    // A material as format 1.8 stored it: 96 bytes, written field by field here (FORMAT.md's
    // `MATL` table): the 80 of version 1, then the coat's strength, roughness and two textures.
    let mut v2 = Vec::new();
    for f in [0.8f32, 0.5, 0.25, 1.0, 0.0, 0.0, 0.0, 1.0, 0.3, 0.5, 1.0, 1.0] {
        v2.extend(f.to_le_bytes());
    }
    for u in [u32::MAX, u32::MAX, u32::MAX, u32::MAX, u32::MAX, 0, 0, 0] {
        v2.extend(u.to_le_bytes());
    }
    for f in [0.75f32, 0.125] {
        v2.extend(f.to_le_bytes());
    }
    for u in [u32::MAX, u32::MAX] {
        v2.extend(u.to_le_bytes());
    }
    assert_eq!(v2.len(), 96);
    let bytes = common::small_file_with_materials(2, &v2);
    let f = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = kiln_format::scene::SceneView::new(&f).unwrap();
    let m = &view.materials[0];
    assert_eq!((m.metallic, m.roughness), (1.0, 0.3));
    assert_eq!((m.clearcoat, m.clearcoat_roughness), (0.75, 0.125));
    assert_eq!((m.clearcoat_texture, m.clearcoat_roughness_texture), (u32::MAX, u32::MAX));
    // No transmission and no transmission texture (not texture 0, which zeroed words would name).
    assert_eq!((m.transmission, m.transmission_texture, m.reserved), (0.0, u32::MAX, [0, 0]));

    // 96 bytes are not a whole version-3 record: refused.
    let mut w = FileWriter::new();
    let err = w.raw(sections::MATERIALS, 0, 3, &v2[..], ContentHash::of(b"m")).unwrap_err();
    assert!(err.to_string().contains("112"), "{err}");
}
