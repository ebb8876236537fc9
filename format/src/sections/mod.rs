//! Section kinds this crate knows, their element types and their streaming order.
//!
//! The table [`KNOWN`] is the one list of kinds: the writer orders sections by it, the reader uses
//! it to check element sizes, and `inspect`/`export` take their names from it.

mod bvh;
mod geometry;
mod material;
mod texture;

pub use bvh::{BVH_TRAVERSAL_STACK, CwbvhNode};
pub use geometry::Vertex;
pub use material::{
    AlphaMode, DIELECTRIC_F0, GpuMaterial, GpuMaterialV1, GpuMaterialV2, MATERIAL_SLOTS, MaterialFlags,
    NO_TEXTURE, material_words,
};
pub use texture::{
    PixelFormat, Swizzle, TEXTURE_HEADER_BYTES, TextureData, TextureHeader, decode_level, decode_texture,
    encode_texture, possible_v2_lengths,
};

use crate::table::SectionKind;

/// The manifest: scene metadata, bincode 2 (see [`crate::manifest`]).
pub const MANIFEST: SectionKind = SectionKind(*b"MANI");
/// Vertices ([`Vertex`]), relative to the manifest's `origin`.
pub const VERTICES: SectionKind = SectionKind(*b"VERT");
/// Texture coordinates (`[f32; 2]`, set 0, glTF convention: v down the image), one per vertex.
pub const UVS: SectionKind = SectionKind(*b"UVS0");
/// Vertex colours (`[u16; 4]` unorm16 linear RGBA, glTF `COLOR_0`), one per vertex; they
/// multiply the base colour. Absent: every vertex is white.
pub const COLORS: SectionKind = SectionKind(*b"COL0");
/// Triangles as three `u32` vertex indices each, in BVH leaf order.
pub const TRIANGLES: SectionKind = SectionKind(*b"TRIS");
/// Material index (`u32`) of each triangle.
pub const TRIANGLE_MATERIALS: SectionKind = SectionKind(*b"TMAT");
/// Materials ([`GpuMaterial`]).
pub const MATERIALS: SectionKind = SectionKind(*b"MATL");
/// One texture's full mip chain, mip 0 first; version 1 bare RGBA8, version 2 a [`TextureHeader`]
/// (pixel format: RGBA8, BC7, BC5 or BC4; swizzle) then the chain; index = texture number.
pub const TEXTURE: SectionKind = SectionKind(*b"TEXL");
/// Compressed wide BVH nodes ([`CwbvhNode`]); root is node 0.
pub const BVH_NODES: SectionKind = SectionKind(*b"CWBV");

/// Voxel grid and line-space header ([`crate::linespace::GridHeader`], one element).
pub const GRID: SectionKind = SectionKind(*b"VGRD");
/// Voxel triangle lists: CSR offsets, `u32` per cell plus one.
pub const VOXEL_OFFSETS: SectionKind = SectionKind(*b"VOXO");
/// Voxel triangle lists: triangle numbers, ascending within a cell.
pub const VOXEL_TRIANGLES: SectionKind = SectionKind(*b"VOXT");
/// Line-space slot of each cell (`u32`, `0xFFFFFFFF` for empty cells).
pub const SHAFT_SLOTS: SectionKind = SectionKind(*b"LSLT");
/// One bit per shaft, `u32` words, `ceil(15 N⁴ / 32)` words per slot.
pub const SHAFT_BITS: SectionKind = SectionKind(*b"LSBN");
/// Filled shafts before each word of `LSBN` (`u32`, a global exclusive prefix count).
pub const SHAFT_RANKS: SectionKind = SectionKind(*b"LSRK");
/// Candidate lists: CSR offsets, `u32` per filled shaft plus one.
pub const CANDIDATE_OFFSETS: SectionKind = SectionKind(*b"LSCO");
/// Candidate list entries (`u32`: cell-local triangle, key bounds).
pub const CANDIDATES: SectionKind = SectionKind(*b"LSCE");
/// PNMT records ([`crate::linespace::PnmtLayout`]), front and back per filled shaft.
pub const PNMT: SectionKind = SectionKind(*b"LSPN");

/// Pre-illuminated line space: front and back radiance per filled shaft (`[u16; 4]` binary16
/// RGB + zero, twice).
pub const PREILLUM: SectionKind = SectionKind(*b"LSPI");
/// BRDF lookup table: `[u16; 2]` unorm16 (R scale, G bias) per texel.
pub const BRDF_LUT: SectionKind = SectionKind(*b"BRDF");
/// One shadow map: f32 depths; index = shadow map number.
pub const SHADOW_MAP: SectionKind = SectionKind(*b"SHDW");
/// Light-visibility volume of one light: u8 per cell; index = position in the manifest's list.
pub const MEDIA_VISIBILITY: SectionKind = SectionKind(*b"MVIS");

/// Mean emitted luminance (`f32`) of each triangle (BVH leaf order) over its area: emission
/// factor × emissive texture; 0 for triangles that do not emit. Present when a material has an
/// emissive texture: the emitter tables weigh triangles by it.
pub const EMITTER_LUMINANCE: SectionKind = SectionKind(*b"EMLU");
/// Irradiance probe volume header ([`crate::probes::ProbeHeader`], one element).
pub const PROBE_GRID: SectionKind = SectionKind(*b"PRBG");
/// Probe states ([`crate::probes::ProbeState`]: offset and on/off), one per probe.
pub const PROBE_STATES: SectionKind = SectionKind(*b"PRBS");
/// Probe irradiance atlas: `E5B9G9R9` texels (see [`crate::probes`]).
pub const PROBE_IRRADIANCE: SectionKind = SectionKind(*b"PRBI");
/// Probe visibility atlas: binary16 (mean, mean square) distance per texel.
pub const PROBE_VISIBILITY: SectionKind = SectionKind(*b"PRBV");
/// Environment header ([`crate::environment::EnvironmentHeader`], one element).
pub const ENVIRONMENT_HEADER: SectionKind = SectionKind(*b"ENVH");
/// Environment radiance map: `E5B9G9R9` texels, equirectangular (see [`crate::environment`]).
pub const ENVIRONMENT_MAP: SectionKind = SectionKind(*b"ENVR");
/// The radiance map prefiltered with GGX lobes of rising roughness: `E5B9G9R9` levels.
pub const ENVIRONMENT_FILTERED: SectionKind = SectionKind(*b"ENVP");
/// The environment's sampling table ([`crate::environment::EnvironmentCell`] per cell).
pub const ENVIRONMENT_TABLE: SectionKind = SectionKind(*b"ENVT");

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
        version: crate::manifest::MANIFEST_VERSION,
        element_size: 1,
        required: true,
        indexed: false,
        description: "scene metadata (bincode 2)",
    },
    KindInfo {
        kind: MATERIALS,
        name: "materials",
        version: 3,
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
        kind: COLORS,
        name: "vertex-colors",
        version: 1,
        element_size: 8,
        required: false,
        indexed: false,
        description: "vertex colours (unorm16 RGBA), multiplying base colour",
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
        version: 2,
        element_size: 4,
        required: false,
        indexed: true,
        description: "mip chain (RGBA8, BC7, BC5 or BC4)",
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
    pod_kind(BRDF_LUT, "brdf-lut", 4, "split-sum BRDF table (unorm16 scale, bias)"),
    KindInfo {
        kind: SHADOW_MAP,
        name: "shadow-map",
        version: 1,
        element_size: 4,
        required: false,
        indexed: true,
        description: "shadow map depths (f32)",
    },
    pod_kind(ENVIRONMENT_HEADER, "environment-header", 192, "environment header and irradiance harmonics"),
    pod_kind(ENVIRONMENT_MAP, "environment-map", 4, "environment radiance map (E5B9G9R9, equirectangular)"),
    pod_kind(
        ENVIRONMENT_FILTERED,
        "environment-filtered",
        4,
        "environment prefiltered for GGX (E5B9G9R9 levels)",
    ),
    pod_kind(ENVIRONMENT_TABLE, "environment-table", 16, "environment sampling table (alias cells)"),
    pod_kind(EMITTER_LUMINANCE, "emitter-luminance", 4, "mean emitted luminance per triangle"),
    pod_kind(PROBE_GRID, "probe-grid", 64, "irradiance probe volume header"),
    pod_kind(PROBE_STATES, "probe-states", 16, "probe offsets and on/off"),
    pod_kind(PROBE_IRRADIANCE, "probe-irradiance", 4, "probe irradiance atlas (E5B9G9R9, octahedral)"),
    pod_kind(PROBE_VISIBILITY, "probe-visibility", 4, "probe distance moments atlas (binary16, octahedral)"),
    KindInfo {
        kind: MEDIA_VISIBILITY,
        name: "media-visibility",
        version: 1,
        element_size: 1,
        required: false,
        indexed: true,
        description: "light visibility per medium cell (unorm8)",
    },
    // Version 2 (format 1.3): the PNMT record layout in the formerly reserved word at 84.
    pod_kind_at(GRID, "voxel-grid", 2, 96, "voxel grid and line-space header"),
    pod_kind(VOXEL_OFFSETS, "voxel-offsets", 4, "voxel triangle list offsets"),
    pod_kind(VOXEL_TRIANGLES, "voxel-triangles", 4, "voxel triangle lists"),
    pod_kind(SHAFT_SLOTS, "shaft-slots", 4, "line-space slot per voxel"),
    pod_kind(SHAFT_BITS, "shaft-bits", 4, "binary line space: one bit per shaft"),
    pod_kind(SHAFT_RANKS, "shaft-ranks", 4, "filled-shaft prefix counts per bit word"),
    pod_kind(CANDIDATE_OFFSETS, "candidate-offsets", 4, "candidate list offsets per filled shaft"),
    pod_kind(CANDIDATES, "candidates", 4, "exact candidate lists per filled shaft"),
    // Version 2 (format 1.3): u32 words of records in the header's layout (version 1: 16-byte
    // records, the full layout).
    pod_kind_at(PNMT, "pnmt", 2, 4, "front and back hit records per filled shaft"),
    pod_kind(PREILLUM, "preillum", 16, "front and back radiance per filled shaft"),
];

/// A non-indexed, optional POD kind at version 1.
const fn pod_kind(
    kind: SectionKind,
    name: &'static str,
    element_size: usize,
    description: &'static str,
) -> KindInfo {
    pod_kind_at(kind, name, 1, element_size, description)
}

/// A non-indexed, optional POD kind at `version`.
const fn pod_kind_at(
    kind: SectionKind,
    name: &'static str,
    version: u16,
    element_size: usize,
    description: &'static str,
) -> KindInfo {
    KindInfo { kind, name, version, element_size, required: false, indexed: false, description }
}

impl KindInfo {
    /// The size of one element in a section of this kind at layout `version`: `element_size`,
    /// except for the older layouts whose elements were smaller (`MATL` versions 1 and 2: 80 and
    /// 96 bytes).
    pub fn element_size_at(&self, version: u16) -> usize {
        if self.kind == MATERIALS && version < self.version {
            4 * material_words(version)
        } else {
            self.element_size
        }
    }
}

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
