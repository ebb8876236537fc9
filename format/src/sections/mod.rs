//! Section kinds this crate knows, their element types and their streaming order.
//!
//! The table [`KNOWN`] is the one list of kinds: the writer orders sections by it, the reader uses
//! it to check element sizes, and `inspect`/`export` take their names from it.

mod bvh;
mod geometry;
mod material;

pub use bvh::{BVH_TRAVERSAL_STACK, CwbvhNode};
pub use geometry::Vertex;
pub use material::{AlphaMode, GpuMaterial, MaterialFlags, NO_TEXTURE};

use crate::table::SectionKind;

/// The manifest: scene metadata, bincode 2 (see [`crate::manifest`]).
pub const MANIFEST: SectionKind = SectionKind(*b"MANI");
/// Vertices ([`Vertex`]), world space.
pub const VERTICES: SectionKind = SectionKind(*b"VERT");
/// Texture coordinates (`[f32; 2]`, set 0, glTF convention: v down the image), one per vertex.
pub const UVS: SectionKind = SectionKind(*b"UVS0");
/// Triangles as three `u32` vertex indices each, in BVH leaf order.
pub const TRIANGLES: SectionKind = SectionKind(*b"TRIS");
/// Material index (`u32`) of each triangle.
pub const TRIANGLE_MATERIALS: SectionKind = SectionKind(*b"TMAT");
/// Materials ([`GpuMaterial`]).
pub const MATERIALS: SectionKind = SectionKind(*b"MATL");
/// One texture's full mip chain, RGBA8, mip 0 first, rows tightly packed; index = texture number.
pub const TEXTURE: SectionKind = SectionKind(*b"TEXL");
/// Compressed wide BVH nodes ([`CwbvhNode`]); root is node 0.
pub const BVH_NODES: SectionKind = SectionKind(*b"CWBV");

/// What the format knows of a section kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KindInfo {
    /// The FourCC.
    pub kind: SectionKind,
    /// Name used by `inspect` and `export`.
    pub name: &'static str,
    /// Newest layout version this crate reads and writes.
    pub version: u16,
    /// Size of one element; the section length must be a multiple of it.
    pub element_size: usize,
    /// Whether a file without it is invalid.
    pub required: bool,
    /// Whether several sections of the kind may exist (distinguished by index).
    pub indexed: bool,
    /// One line for `inspect`.
    pub description: &'static str,
}

/// Every kind this crate knows, in streaming order: what the first frame needs comes first.
pub const KNOWN: &[KindInfo] = &[
    KindInfo {
        kind: MANIFEST,
        name: "manifest",
        version: 1,
        element_size: 1,
        required: true,
        indexed: false,
        description: "scene metadata (bincode 2)",
    },
    KindInfo {
        kind: MATERIALS,
        name: "materials",
        version: 1,
        element_size: size_of::<GpuMaterial>(),
        required: false,
        indexed: false,
        description: "PBR materials",
    },
    KindInfo {
        kind: VERTICES,
        name: "vertices",
        version: 1,
        element_size: size_of::<Vertex>(),
        required: false,
        indexed: false,
        description: "world-space vertices (position, normal)",
    },
    KindInfo {
        kind: UVS,
        name: "uvs",
        version: 1,
        element_size: 8,
        required: false,
        indexed: false,
        description: "texture coordinates per vertex",
    },
    KindInfo {
        kind: TRIANGLES,
        name: "triangles",
        version: 1,
        element_size: 12,
        required: false,
        indexed: false,
        description: "vertex indices, BVH leaf order",
    },
    KindInfo {
        kind: TRIANGLE_MATERIALS,
        name: "triangle-materials",
        version: 1,
        element_size: 4,
        required: false,
        indexed: false,
        description: "material index per triangle",
    },
    KindInfo {
        kind: TEXTURE,
        name: "texture",
        version: 1,
        element_size: 4,
        required: false,
        indexed: true,
        description: "RGBA8 mip chain",
    },
    KindInfo {
        kind: BVH_NODES,
        name: "bvh",
        version: 1,
        element_size: size_of::<CwbvhNode>(),
        required: false,
        indexed: false,
        description: "compressed wide BVH (8-ary) nodes",
    },
];

/// What this crate knows of `kind`, if anything.
pub fn info(kind: SectionKind) -> Option<&'static KindInfo> {
    KNOWN.iter().find(|k| k.kind == kind)
}

/// The kind with this `inspect` name, if any.
pub fn by_name(name: &str) -> Option<&'static KindInfo> {
    KNOWN.iter().find(|k| k.name == name)
}

/// Position of `kind` in the streaming order; unknown kinds sort last.
pub fn stream_rank(kind: SectionKind) -> usize {
    KNOWN.iter().position(|k| k.kind == kind).unwrap_or(KNOWN.len())
}
