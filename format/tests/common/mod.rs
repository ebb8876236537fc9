//! Fixtures shared by the format tests: a small but complete scene file.

use kiln_format::manifest::*;
use kiln_format::sections::{self, CwbvhNode, GpuMaterial, Vertex};
use kiln_format::{Compression, ContentHash, FileWriter};

/// A one-quad scene with the geometry, material, texture and BVH kinds (a valid one-node BVH and
/// a 2x2 texture), written by the reference writer. Every kind the format knows, line space,
/// BRDF table, shadow maps and visibility volumes included, is in the compiler's damage fixture
/// (`compiler/tests/damage.rs`, `every_kind_file`).
#[allow(dead_code)] // Not every test binary that includes this module uses it.
pub fn small_file() -> Vec<u8> {
    small_file_with(2, Compression::None)
}

/// [`small_file`] with a `texture` × `texture` texture (a compressible pattern: zstd shrinks it
/// when it is large enough) and its sections compressed as `compression` says.
#[allow(dead_code)] // Not every test binary that includes this module uses it.
pub fn small_file_with(texture: u32, compression: Compression) -> Vec<u8> {
    let materials = [GpuMaterial { base_color_texture: 0, ..Default::default() }];
    small_file_built(
        texture,
        compression,
        sections::info(sections::MATERIALS).unwrap().version,
        bytemuck::cast_slice(&materials),
    )
}

/// [`small_file`] with its one material's `MATL` section given as bytes at layout `version`.
#[allow(dead_code)] // Not every test binary that includes this module uses it.
pub fn small_file_with_materials(version: u16, materials: &[u8]) -> Vec<u8> {
    small_file_built(2, Compression::None, version, materials)
}

fn small_file_built(texture: u32, compression: Compression, matl_version: u16, materials: &[u8]) -> Vec<u8> {
    let vertices = [
        Vertex { position: [0.0, 0.0, 0.0], normal: [0.0, 0.0, 1.0] },
        Vertex { position: [1.0, 0.0, 0.0], normal: [0.0, 0.0, 1.0] },
        Vertex { position: [1.0, 1.0, 0.0], normal: [0.0, 0.0, 1.0] },
        Vertex { position: [0.0, 1.0, 0.0], normal: [0.0, 0.0, 1.0] },
    ];
    let uvs: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let triangles: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];
    let tmat = [0u32, 0];
    // One root with one leaf of two triangles; box [0,1]^2 x [0, 0].
    // Steps of 1/128: 128 steps reach 1 exactly, so the box holds the quad (FORMAT.md's must).
    let mut root = CwbvhNode { p: [0.0; 3], e: [127 - 7, 127 - 7, 127 - 7], ..Default::default() };
    root.child_meta[0] = 0b0110_0000;
    root.child_max_x[0] = 128;
    root.child_max_y[0] = 128;
    let nodes = [root];
    let mip_levels = kiln_format::scene::mip_levels(texture, texture);
    let texel_count: u32 = (0..mip_levels).map(|l| (texture >> l).max(1).pow(2)).sum();
    // 2×2: the bytes 0..20 as before; larger: runs of a few values, which zstd shrinks.
    let texels: Vec<u8> =
        (0..texel_count * 4).map(|i| if texture <= 2 { i as u8 } else { (i / 12 % 5 * 40) as u8 }).collect();
    let manifest = Manifest {
        generator: "test".into(),
        scene_name: "quad".into(),
        bounds: Bounds { min: [0.0; 3], max: [1.0, 1.0, 0.0] },
        materials: vec![MaterialInfo { name: "m".into() }],
        textures: vec![TextureInfo {
            name: "t".into(),
            width: texture,
            height: texture,
            mip_levels,
            color_space: ColorSpace::Srgb,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::ClampToEdge,
            mag_linear: true,
        }],
        lights: vec![Light {
            name: "l".into(),
            kind: LightKind::Point,
            position: [0.5, 0.5, 1.0],
            direction: [0.0, 0.0, -1.0],
            right: [0.0; 3],
            color: [1.0; 3],
            intensity: 2.0,
            range: 0.0,
            casts_shadows: true,
        }],
        ..Default::default()
    };
    let h = ContentHash::of;
    let mut w = FileWriter::new();
    w.compression(compression);
    w.manifest(&manifest, h(b"m")).unwrap();
    w.pod(sections::VERTICES, 0, &vertices, h(b"v")).unwrap();
    w.pod(sections::UVS, 0, &uvs, h(b"uv")).unwrap();
    w.pod(sections::TRIANGLES, 0, &triangles, h(b"t")).unwrap();
    w.pod(sections::TRIANGLE_MATERIALS, 0, &tmat, h(b"tm")).unwrap();
    w.raw(sections::MATERIALS, 0, matl_version, materials, h(b"mat")).unwrap();
    w.pod(sections::BVH_NODES, 0, &nodes, h(b"b")).unwrap();
    // A version-2 texture section: the 16-byte header (RGBA8, identity swizzle), then the chain.
    let texture =
        sections::encode_texture(sections::PixelFormat::Rgba8, sections::Swizzle::IDENTITY, &texels);
    w.bytes(sections::TEXTURE, 0, texture, h(b"tex")).unwrap();
    w.to_bytes().unwrap()
}
