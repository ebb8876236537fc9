//! A second reader of `.kiln` files, written from `format/FORMAT.md`'s tables alone (not from
//! `kiln-format`), so that the specification and the reference reader cannot drift apart
//! silently. It decodes the header, the section table and every checksum, the whole manifest
//! (bincode 2 by the spec's rules), `VERT`, `UVS0`, `TRIS`, `TMAT`, `MATL`, the CWBVH node layout
//! and tree, and the voxel grid with the binary, candidate and PNMT line-space variants, and
//! compares every value with what `KilnFile`, `SceneView` and `LineSpace` read. Where the spec
//! makes a promise about the contents (decoded boxes contain their triangles, the grid covers
//! the bounds by four margins, a ray's shaft is filled and lists the triangles it hits, PNMT
//! records are the segment's first hits), the promise is checked with arithmetic written here.
//!
//! Kiln types (`Manifest`, `Light`, ...) serve only as containers for the comparison: every byte
//! is interpreted by this file.

#[path = "util/run.rs"]
mod run;

use kiln_compiler::import::demo::cornell_box;
use kiln_compiler::ir::{Texture, TextureRole};
use kiln_compiler::pipeline::compile_to_bytes;
use kiln_compiler::settings::{Codec, Settings, VoxelRes};
use kiln_format::linespace::{LineSpace, Variants};
use kiln_format::manifest::{
    Bounds, BrdfLutInfo, Camera, ColorSpace, InputFile, Light, LightKind, Manifest, MaterialInfo,
    MediaVisibilityInfo, Medium, OrthographicCamera, Setting, ShadowMapInfo, ShadowProjection, SkippedStage,
    Sky, TextureInfo, Wrap,
};
use kiln_format::{Checksums, KilnFile, SceneView};
use std::path::{Path, PathBuf};

/// The decoder. Nothing in here calls `kiln-format`.
mod spec {
    use xxhash_rust::xxh3::{xxh3_64, xxh3_128};

    /// One table entry as FORMAT.md lays it out.
    #[derive(Debug, Clone, PartialEq, Eq)]
    pub struct Entry {
        pub kind: [u8; 4],
        pub version: u16,
        pub codec: u8,
        pub align_log2: u8,
        pub index: u32,
        pub flags: u32,
        pub offset: u64,
        pub size: u64,
        pub raw_size: u64,
        pub checksum: u64,
        pub content_hash: [u8; 16],
    }

    pub fn u16_at(b: &[u8], o: usize) -> u16 {
        u16::from_le_bytes(b[o..o + 2].try_into().unwrap())
    }
    pub fn u32_at(b: &[u8], o: usize) -> u32 {
        u32::from_le_bytes(b[o..o + 4].try_into().unwrap())
    }
    pub fn u64_at(b: &[u8], o: usize) -> u64 {
        u64::from_le_bytes(b[o..o + 8].try_into().unwrap())
    }
    pub fn f32_at(b: &[u8], o: usize) -> f32 {
        f32::from_le_bytes(b[o..o + 4].try_into().unwrap())
    }
    pub fn f64_at(b: &[u8], o: usize) -> f64 {
        f64::from_le_bytes(b[o..o + 8].try_into().unwrap())
    }
    pub fn f32s<const K: usize>(b: &[u8], o: usize) -> [f32; K] {
        std::array::from_fn(|i| f32_at(b, o + 4 * i))
    }
    pub fn u32s(b: &[u8]) -> Vec<u32> {
        assert_eq!(b.len() % 4, 0);
        (0..b.len() / 4).map(|i| u32_at(b, 4 * i)).collect()
    }

    /// A checked file: header, table, placement, padding and section checksums, every section
    /// decoded.
    pub struct File<'a> {
        pub version: (u16, u16),
        pub entries: Vec<Entry>,
        /// Decoded bytes per entry: the stored bytes for codec 0, the zstd frame's content for 1.
        pub decoded: Vec<std::borrow::Cow<'a, [u8]>>,
    }

    impl File<'_> {
        /// The decoded bytes of `(kind, index)`, if present.
        pub fn section(&self, kind: &[u8; 4], index: u32) -> Option<&[u8]> {
            let i = self.entries.iter().position(|e| &e.kind == kind && e.index == index)?;
            Some(&self.decoded[i])
        }
    }

    /// The decoding limit this reader chooses (FORMAT.md lets each reader choose one).
    pub const MAX_DECODED: u64 = 1 << 32;

    /// Codec 1 by FORMAT.md "Codecs": exactly one zstd frame (not skippable), declaring a content
    /// size equal to `raw_size`, decoding to exactly that many bytes. Decoded with the zstd crate
    /// (the reference library), never with kiln-format.
    pub fn decode_zstd(stored: &[u8], raw_size: u64) -> Result<Vec<u8>, String> {
        use zstd::zstd_safe;
        if raw_size > MAX_DECODED {
            return Err("raw_size beyond the limit".into());
        }
        if stored.len() < 4 || u32_at(stored, 0) != 0xFD2F_B528 {
            return Err("zstd magic".into());
        }
        if zstd_safe::find_frame_compressed_size(stored) != Ok(stored.len()) {
            return Err("not exactly one zstd frame".into());
        }
        if !matches!(zstd_safe::get_frame_content_size(stored), Ok(Some(n)) if n == raw_size) {
            return Err("frame content size".into());
        }
        let mut out = vec![0u8; raw_size as usize];
        let n = zstd::bulk::Decompressor::new()
            .and_then(|mut d| d.decompress_to_buffer(stored, &mut out[..]))
            .map_err(|e| format!("zstd: {e}"))?;
        if n as u64 != raw_size {
            return Err("decoded length".into());
        }
        Ok(out)
    }

    /// Header, table, placement and checksums; `Err` names the first rule broken.
    pub fn open(b: &[u8]) -> Result<File<'_>, String> {
        if b.len() < 64 || b[0..8] != [0x89, b'K', b'L', b'N', 0x0D, 0x0A, 0x1A, 0x0A] {
            return Err("magic".into());
        }
        if u16_at(b, 8) != 1 {
            return Err("major version".into());
        }
        if xxh3_64(&b[0..56]) != u64_at(b, 56) {
            return Err("header checksum".into());
        }
        if u32_at(b, 12) & 0xFFFF != 0 {
            return Err("required flag".into());
        }
        let count = u32_at(b, 20) as u64;
        if u32_at(b, 16) != 64 || u64_at(b, 24) != 64 || u64_at(b, 48) != 0 {
            return Err("header fields".into());
        }
        if u64_at(b, 32) != b.len() as u64 {
            return Err("file_size".into());
        }
        let table_end = 64 + 64 * count;
        if table_end > b.len() as u64 {
            return Err("table beyond the file".into());
        }
        let table = &b[64..table_end as usize];
        if xxh3_64(table) != u64_at(b, 40) {
            return Err("table checksum".into());
        }
        let mut cursor = table_end;
        let mut entries: Vec<Entry> = Vec::new();
        for e in table.chunks_exact(64) {
            let entry = Entry {
                kind: e[0..4].try_into().unwrap(),
                version: u16_at(e, 4),
                codec: e[6],
                align_log2: e[7],
                index: u32_at(e, 8),
                flags: u32_at(e, 12),
                offset: u64_at(e, 16),
                size: u64_at(e, 24),
                raw_size: u64_at(e, 32),
                checksum: u64_at(e, 40),
                content_hash: e[48..64].try_into().unwrap(),
            };
            if !(6..=16).contains(&entry.align_log2) || entry.flags != 0 || entry.version == 0 {
                return Err("entry fields".into());
            }
            match entry.codec {
                0 if entry.raw_size == entry.size => {}
                1 if entry.raw_size <= MAX_DECODED => {}
                _ => return Err("codec".into()),
            }
            let align = 1u64 << entry.align_log2;
            if entry.offset != cursor.div_ceil(align) * align {
                return Err("placement".into());
            }
            let end = entry.offset.checked_add(entry.size).filter(|&e| e <= b.len() as u64);
            let Some(end) = end else { return Err("section beyond the file".into()) };
            if b[cursor as usize..entry.offset as usize].iter().any(|&x| x != 0) {
                return Err("padding".into());
            }
            if xxh3_64(&b[entry.offset as usize..end as usize]) != entry.checksum {
                return Err("section checksum".into());
            }
            if entries.iter().any(|o| (o.kind, o.index) == (entry.kind, entry.index)) {
                return Err("duplicate".into());
            }
            cursor = end;
            entries.push(entry);
        }
        if cursor != b.len() as u64 {
            return Err("trailing bytes".into());
        }
        if !entries.iter().any(|e| &e.kind == b"MANI") {
            return Err("no manifest".into());
        }
        let mut decoded = Vec::with_capacity(entries.len());
        for e in &entries {
            let stored = &b[e.offset as usize..(e.offset + e.size) as usize];
            decoded.push(match e.codec {
                0 => std::borrow::Cow::Borrowed(stored),
                _ => std::borrow::Cow::Owned(decode_zstd(stored, e.raw_size)?),
            });
        }
        Ok(File { version: (u16_at(b, 8), u16_at(b, 10)), entries, decoded })
    }

    /// A 128-bit hash as FORMAT.md writes it: hex of the stored (little-endian) bytes.
    pub fn hash_hex(bytes: &[u8]) -> String {
        xxh3_128(bytes).to_le_bytes().iter().map(|b| format!("{b:02x}")).collect()
    }

    /// The manifest's bincode, by the table in FORMAT.md (`MANI`).
    pub struct Bin<'a> {
        pub b: &'a [u8],
        pub at: usize,
    }

    impl Bin<'_> {
        fn take(&mut self, n: usize) -> &[u8] {
            let s = &self.b[self.at..self.at + n];
            self.at += n;
            s
        }
        fn byte(&mut self) -> u8 {
            self.take(1)[0]
        }
        /// A varint of a type `width` bytes wide.
        fn varint(&mut self, width: usize) -> u64 {
            let tag = self.byte();
            let n = match tag {
                0..=250 => return tag as u64,
                251 => 2,
                252 => 4,
                253 => 8,
                _ => panic!("varint tag {tag:#x} at {}", self.at - 1),
            };
            assert!(n <= width, "varint tag {tag:#x} wider than a {width}-byte type");
            let mut v = [0u8; 8];
            v[..n].copy_from_slice(self.take(n));
            u64::from_le_bytes(v)
        }
        pub fn u32(&mut self) -> u32 {
            self.varint(4) as u32
        }
        pub fn u64(&mut self) -> u64 {
            self.varint(8)
        }
        pub fn f32(&mut self) -> f32 {
            f32::from_le_bytes(self.take(4).try_into().unwrap())
        }
        pub fn f3(&mut self) -> [f32; 3] {
            [self.f32(), self.f32(), self.f32()]
        }
        pub fn f64(&mut self) -> f64 {
            f64::from_le_bytes(self.take(8).try_into().unwrap())
        }
        pub fn bool(&mut self) -> bool {
            match self.byte() {
                0 => false,
                1 => true,
                x => panic!("bool {x}"),
            }
        }
        pub fn string(&mut self) -> String {
            let n = self.u64() as usize;
            String::from_utf8(self.take(n).to_vec()).expect("UTF-8")
        }
        pub fn vec<T>(&mut self, mut f: impl FnMut(&mut Self) -> T) -> Vec<T> {
            let n = self.u64() as usize;
            (0..n).map(|_| f(self)).collect()
        }
        pub fn option<T>(&mut self, f: impl FnOnce(&mut Self) -> T) -> Option<T> {
            match self.byte() {
                0 => None,
                1 => Some(f(self)),
                x => panic!("option tag {x}"),
            }
        }
        /// An enum's variant index, below `count`.
        pub fn variant(&mut self, count: u32) -> u32 {
            let v = self.u32();
            assert!(v < count, "variant {v} of {count}");
            v
        }
    }

    /// IEEE binary16 to f32.
    pub fn half(h: u16) -> f32 {
        let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
        let (e, m) = ((h >> 10) & 0x1f, (h & 0x3ff) as f32);
        sign * match e {
            0 => m * 2f32.powi(-24),
            31 => {
                if m == 0.0 {
                    f32::INFINITY
                } else {
                    f32::NAN
                }
            }
            _ => (1.0 + m / 1024.0) * 2f32.powi(e as i32 - 15),
        }
    }
}

/// The whole manifest, field by field in FORMAT.md's order.
fn decode_manifest(b: &[u8]) -> Manifest {
    use spec::Bin;
    let mut r = Bin { b, at: 0 };
    let bounds = |r: &mut Bin| Bounds { min: r.f3(), max: r.f3() };
    let wrap = |r: &mut Bin| [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge][r.variant(3) as usize];
    let m = Manifest {
        generator: r.string(),
        scene_name: r.string(),
        inputs: r.vec(|r| InputFile { path: r.string(), bytes: r.u64(), hash: r.string() }),
        settings: r.vec(|r| Setting { key: r.string(), value: r.string() }),
        bounds: bounds(&mut r),
        materials: r.vec(|r| MaterialInfo { name: r.string() }),
        textures: r.vec(|r| TextureInfo {
            name: r.string(),
            width: r.u32(),
            height: r.u32(),
            mip_levels: r.u32(),
            color_space: [ColorSpace::Srgb, ColorSpace::Linear][r.variant(2) as usize],
            wrap_u: wrap(r),
            wrap_v: wrap(r),
            mag_linear: r.bool(),
        }),
        lights: r.vec(|r| Light {
            name: r.string(),
            kind: match r.variant(4) {
                0 => LightKind::Point,
                1 => LightKind::Spot { inner_cone: r.f32(), outer_cone: r.f32() },
                2 => LightKind::Directional,
                _ => LightKind::Rect { width: r.f32(), height: r.f32() },
            },
            position: r.f3(),
            direction: r.f3(),
            right: r.f3(),
            color: r.f3(),
            intensity: r.f32(),
            range: r.f32(),
            casts_shadows: r.bool(),
        }),
        cameras: r.vec(|r| Camera {
            name: r.string(),
            position: r.f3(),
            target: r.f3(),
            up: r.f3(),
            vfov_degrees: r.f32(),
            znear: r.f32(),
            zfar: r.f32(),
        }),
        sky: Sky { radiance: r.f3() },
        media: r.vec(|r| Medium { bounds: bounds(r), sigma_a: r.f3(), sigma_s: r.f3(), g: r.f32() }),
        skipped: r.vec(|r| SkippedStage { stage: r.string(), reason: r.string() }),
        degenerate_triangles: r.u64(),
        brdf_lut: r.option(|r| BrdfLutInfo { resolution: r.u32(), samples: r.u32() }),
        shadow_maps: r.vec(|r| ShadowMapInfo {
            light: r.u32(),
            projection: [
                ShadowProjection::Orthographic,
                ShadowProjection::Perspective,
                ShadowProjection::Cube,
            ][r.variant(3) as usize],
            resolution: r.u32(),
            view_proj: std::array::from_fn(|_| r.f32()),
            origin: r.f3(),
            direction: r.f3(),
            near: r.f32(),
            far: r.f32(),
            texel: r.f32(),
        }),
        media_visibility: r.option(|r| MediaVisibilityInfo {
            medium: r.u32(),
            dims: [r.u32(), r.u32(), r.u32()],
            samples: r.u32(),
            lights: r.vec(|r| r.u32()),
        }),
        // Manifest version 2 appends the orthographic cameras; version 1 ends here.
        orthographic: Vec::new(),
        // Version 3 appends the origin; version 2 ends before it.
        origin: [0.0; 3],
    };
    let mut m = m;
    if r.at < b.len() {
        m.orthographic = r.vec(|r| OrthographicCamera { camera: r.u32(), xmag: r.f32(), ymag: r.f32() });
    }
    if r.at < b.len() {
        m.origin = [r.f64(), r.f64(), r.f64()];
    }
    assert_eq!(r.at, b.len(), "no bytes after the last field");
    m
}

/// Geometry as FORMAT.md lays it out.
struct Geometry {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    colors: Vec<[u16; 4]>,
    tris: Vec<[u32; 3]>,
    tmat: Vec<u32>,
}

fn decode_geometry(f: &spec::File) -> Geometry {
    use spec::*;
    let vert = f.section(b"VERT", 0).unwrap_or(&[]);
    assert_eq!(vert.len() % 24, 0);
    let tris = f.section(b"TRIS", 0).unwrap_or(&[]);
    assert_eq!(tris.len() % 12, 0);
    let uvs = f.section(b"UVS0", 0).unwrap_or(&[]);
    assert_eq!(uvs.len() % 8, 0);
    let colors = f.section(b"COL0", 0).unwrap_or(&[]);
    assert_eq!(colors.len() % 8, 0);
    Geometry {
        positions: (0..vert.len() / 24).map(|i| f32s::<3>(vert, 24 * i)).collect(),
        normals: (0..vert.len() / 24).map(|i| f32s::<3>(vert, 24 * i + 12)).collect(),
        uvs: (0..uvs.len() / 8).map(|i| f32s::<2>(uvs, 8 * i)).collect(),
        colors: colors
            .chunks_exact(8)
            .map(|c| std::array::from_fn(|k| u16::from_le_bytes([c[2 * k], c[2 * k + 1]])))
            .collect(),
        tris: (0..tris.len() / 12).map(|i| std::array::from_fn(|k| u32_at(tris, 12 * i + 4 * k))).collect(),
        tmat: u32s(f.section(b"TMAT", 0).unwrap_or(&[])),
    }
}

/// One CWBVH node at its FORMAT.md offsets.
#[derive(Debug, PartialEq)]
struct Node {
    p: [f32; 3],
    e: [u8; 3],
    imask: u8,
    child_base: u32,
    prim_base: u32,
    meta: [u8; 8],
    /// min x, max x, min y, max y, min z, max z.
    q: [[u8; 8]; 6],
}

fn decode_bvh(f: &spec::File) -> Vec<Node> {
    use spec::*;
    let b = f.section(b"CWBV", 0).unwrap_or(&[]);
    assert_eq!(b.len() % 80, 0);
    b.chunks_exact(80)
        .map(|n| Node {
            p: f32s::<3>(n, 0),
            e: [n[12], n[13], n[14]],
            imask: n[15],
            child_base: u32_at(n, 16),
            prim_base: u32_at(n, 20),
            meta: n[24..32].try_into().unwrap(),
            q: std::array::from_fn(|k| n[32 + 8 * k..40 + 8 * k].try_into().unwrap()),
        })
        .collect()
}

/// Walks the tree from the root by FORMAT.md's child and leaf rules: every node reached once,
/// every triangle in exactly one leaf, and every decoded child box (`p + 2^(e−127)·q` in f32)
/// containing its subtree's triangles. Returns the subtree box of `n`.
fn walk(
    nodes: &[Node],
    g: &Geometry,
    n: usize,
    seen: &mut [u32],
    leaves: &mut [u32],
    bad: &mut Vec<String>,
) -> [[f32; 3]; 2] {
    seen[n] += 1;
    let node = &nodes[n];
    let mut all = [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]];
    let mut internal = 0;
    for i in 0..8 {
        let meta = node.meta[i];
        if meta == 0 {
            assert_eq!(node.imask & (1 << i), 0, "node {n}: empty slot {i} in imask");
            continue;
        }
        let sub = if node.imask & (1 << i) != 0 {
            assert_eq!(meta, 0b001_00000 | (24 + i as u8), "node {n} slot {i}: internal meta");
            let child = node.child_base as usize + internal;
            internal += 1;
            walk(nodes, g, child, seen, leaves, bad)
        } else {
            let count = match meta >> 5 {
                0b001 => 1,
                0b011 => 2,
                0b111 => 3,
                x => panic!("node {n} slot {i}: count bits {x:03b}"),
            };
            let first = node.prim_base as usize + (meta & 0x1f) as usize;
            let mut b = [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]];
            for (seen, tri) in leaves[first..first + count].iter_mut().zip(&g.tris[first..first + count]) {
                *seen += 1;
                for &v in tri {
                    let p = g.positions[v as usize];
                    b[0] = std::array::from_fn(|a| b[0][a].min(p[a]));
                    b[1] = std::array::from_fn(|a| b[1][a].max(p[a]));
                }
            }
            b
        };
        for a in 0..3 {
            assert!(node.e[a] != 0 && node.e[a] != 255, "node {n}: exponent {}", node.e[a]);
            let step = f32::from_bits((node.e[a] as u32) << 23);
            let lo = node.p[a] + step * node.q[2 * a][i] as f32;
            let hi = node.p[a] + step * node.q[2 * a + 1][i] as f32;
            if lo > sub[0][a] || hi < sub[1][a] {
                bad.push(format!(
                    "node {n} slot {i} axis {a}: decoded [{lo}, {hi}], exact [{}, {}]",
                    sub[0][a], sub[1][a]
                ));
            }
            all[0][a] = all[0][a].min(sub[0][a]);
            all[1][a] = all[1][a].max(sub[1][a]);
        }
    }
    assert_eq!(internal, node.imask.count_ones() as usize);
    all
}

/// The voxel grid and line space as FORMAT.md lays them out.
struct Grid {
    origin: [f64; 3],
    cell: f64,
    margin: f64,
    dims: [u32; 3],
    n: u32,
    variants: u32,
    slots_count: u32,
    filled: u64,
    entries_count: u64,
    max_cell_triangles: u32,
    voxo: Vec<u32>,
    voxt: Vec<u32>,
    slots: Vec<u32>,
    bits: Vec<u32>,
    ranks: Vec<u32>,
    cand_offsets: Vec<u32>,
    cands: Vec<u32>,
    /// `VGRD.pnmt_layout`: 0 full, 1 compact, 2 compact without uv.
    pnmt_layout: u32,
    /// Each record's bytes (16, 12 or 8 by the layout).
    pnmt: Vec<Vec<u8>>,
    preillum: Vec<[u16; 8]>,
}

/// A PNMT record's cell-local position, material, normal and uv.
type RecordFields = ([f64; 3], u32, [f64; 3], [f32; 2]);

/// A PNMT record's fields by FORMAT.md ("`LSPN`: PNMT records"); `None`: no record.
fn pnmt_fields(layout: u32, rec: &[u8]) -> Option<RecordFields> {
    use spec::*;
    if layout == 0 {
        let material = u16_at(rec, 6) as u32;
        let pos = [0, 2, 4].map(|o| u16_at(rec, o) as f64 / 65535.0);
        let e = [8, 10].map(|o| u16_at(rec, o) as i16 as f64 / 32767.0);
        let uv = [half(u16_at(rec, 12)), half(u16_at(rec, 14))];
        return (material != 0xFFFF).then(|| (pos, material, oct_decode(e), uv));
    }
    let (w0, w1) = (u32_at(rec, 0), u32_at(rec, 4));
    let material = (w1 >> 22) | (w0 >> 30) << 10;
    let pos = [0, 10, 20].map(|sh| ((w0 >> sh) & 0x3FF) as f64 / 1023.0);
    let e = [0, 11].map(|sh| (((w1 >> sh) & 0x7FF) as f64 - 1023.0) / 1023.0);
    let uv = if layout == 1 { [half(u16_at(rec, 8)), half(u16_at(rec, 10))] } else { [0.0; 2] };
    (material != 0xFFF).then(|| (pos, material, oct_decode(e), uv))
}

impl Grid {
    fn decode(f: &spec::File) -> Option<Grid> {
        use spec::*;
        let h = f.section(b"VGRD", 0)?;
        assert_eq!(h.len(), 96);
        assert!(h[88..96].iter().all(|&x| x == 0), "reserved");
        let pnmt_layout = u32_at(h, 84);
        let words = match pnmt_layout {
            0 => 4,
            1 => 3,
            2 => 2,
            other => panic!("PNMT layout {other}"),
        };
        let u32s_of = |k: &[u8; 4]| u32s(f.section(k, 0).unwrap_or(&[]));
        let pnmt = f.section(b"LSPN", 0).unwrap_or(&[]);
        Some(Grid {
            origin: [f64_at(h, 0), f64_at(h, 8), f64_at(h, 16)],
            cell: f64_at(h, 24),
            margin: f64_at(h, 32),
            dims: [u32_at(h, 40), u32_at(h, 44), u32_at(h, 48)],
            n: u32_at(h, 52),
            variants: u32_at(h, 56),
            slots_count: u32_at(h, 60),
            filled: u64_at(h, 64),
            entries_count: u64_at(h, 72),
            max_cell_triangles: u32_at(h, 80),
            voxo: u32s_of(b"VOXO"),
            voxt: u32s_of(b"VOXT"),
            slots: u32s_of(b"LSLT"),
            bits: u32s_of(b"LSBN"),
            ranks: u32s_of(b"LSRK"),
            cand_offsets: u32s_of(b"LSCO"),
            cands: u32s_of(b"LSCE"),
            pnmt_layout,
            pnmt: pnmt.chunks_exact(4 * words).map(|r| r.to_vec()).collect(),
            preillum: f
                .section(b"LSPI", 0)
                .unwrap_or(&[])
                .chunks_exact(16)
                .map(|r| std::array::from_fn(|k| u16_at(r, 2 * k)))
                .collect(),
        })
    }
    fn cells(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }
    fn words(&self) -> usize {
        (15 * self.n.pow(4) as usize).div_ceil(32)
    }
    fn cell_tris(&self, c: usize) -> &[u32] {
        &self.voxt[self.voxo[c] as usize..self.voxo[c + 1] as usize]
    }
    fn cell_min(&self, c: usize) -> [f64; 3] {
        let (dx, dy) = (self.dims[0] as usize, self.dims[1] as usize);
        let xyz = [c % dx, (c / dx) % dy, c / (dx * dy)];
        std::array::from_fn(|a| self.origin[a] + self.cell * xyz[a] as f64)
    }
    /// `LSRK[w] + popcount(LSBN[w] & (bit − 1))`, or `None` when the shaft is empty.
    fn rank(&self, slot: u32, shaft: u32) -> Option<usize> {
        let w = slot as usize * self.words() + shaft as usize / 32;
        let bit = 1u32 << (shaft % 32);
        (self.bits[w] & bit != 0)
            .then(|| self.ranks[w] as usize + (self.bits[w] & (bit - 1)).count_ones() as usize)
    }
    fn entries(&self, rank: usize) -> &[u32] {
        &self.cands[self.cand_offsets[rank] as usize..self.cand_offsets[rank + 1] as usize]
    }
}

/// The faces and patches of shaft `s` ("Shafts": pair·N⁴ + patch_a·N² + patch_b).
fn shaft_parts(s: u32, n: u32) -> (u32, u32, u32, u32) {
    let n2 = n * n;
    let pair = s / (n2 * n2);
    let (a, b) = (0..6u32)
        .flat_map(|a| (a + 1..6).map(move |b| (a, b)))
        .find(|&(a, b)| a * (11 - a) / 2 + b - a - 1 == pair)
        .unwrap();
    (a, (s % (n2 * n2)) / n2, b, s % n2)
}

/// The (u, v) axes of a face: the other two in increasing order.
fn uv_axes(face: u32) -> (usize, usize) {
    match face / 2 {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// Cell-local centre of `patch` on `face`.
fn patch_centre(face: u32, patch: u32, n: u32) -> [f64; 3] {
    let (ua, va) = uv_axes(face);
    let mut p = [0.0; 3];
    p[face as usize / 2] = (face % 2) as f64;
    p[ua] = ((patch / n) as f64 + 0.5) / n as f64;
    p[va] = ((patch % n) as f64 + 0.5) / n as f64;
    p
}

/// Segment `a + t·(b − a)`, t in [0, 1], against a triangle's plane in f64: `(t, u, v)` of the
/// crossing, with `margin` the least distance of t and the barycentrics from 0 (and t from 1);
/// negative when the crossing is outside the triangle or the segment.
fn segment_hit(a: [f64; 3], b: [f64; 3], tri: [[f64; 3]; 3]) -> Option<(f64, f64, f64, f64)> {
    let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let cross = |x: [f64; 3], y: [f64; 3]| {
        [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]
    };
    let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let d = sub(b, a);
    let (e1, e2) = (sub(tri[1], tri[0]), sub(tri[2], tri[0]));
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = sub(a, tri[0]);
    let u = dot(s, p) / det;
    let q = cross(s, e1);
    let v = dot(d, q) / det;
    let t = dot(e2, q) / det;
    Some((t, u, v, u.min(v).min(1.0 - u - v).min(t).min(1.0 - t)))
}

/// Octahedral decode, FORMAT.md "PNMT records", from `e` in [-1, 1]².
fn oct_decode([ex, ey]: [f64; 2]) -> [f64; 3] {
    let sgn = |v: f64| if v >= 0.0 { 1.0 } else { -1.0 };
    let z = 1.0 - ex.abs() - ey.abs();
    let t = (-z).max(0.0);
    let v = [ex - t * sgn(ex), ey - t * sgn(ey), z];
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / l)
}

/// Everything the spec lets this reader check about the grid and line space, and agreement with
/// `LineSpace`. Returns (lines tested, lines that hit a triangle, PNMT records checked).
fn check_grid(g: &Grid, geo: &Geometry, manifest: &Manifest, ls: &LineSpace) -> (usize, usize, usize) {
    let h = &ls.header;
    assert_eq!(
        (
            g.origin,
            g.cell,
            g.margin,
            g.dims,
            g.n,
            g.variants,
            g.slots_count,
            g.filled,
            g.entries_count,
            g.max_cell_triangles
        ),
        (
            h.origin,
            h.cell,
            h.margin,
            h.dims,
            h.shaft_res,
            h.variants,
            h.slots,
            h.filled,
            h.entries,
            h.max_cell_triangles
        )
    );
    // "The grid covers the scene bounds widened by four of its own margins", in f64.
    for a in 0..3 {
        let (lo, hi) = (manifest.bounds.min[a] as f64, manifest.bounds.max[a] as f64);
        assert!(
            g.origin[a] <= lo - 4.0 * g.margin,
            "axis {a}: origin {} > {lo} − 4·{}",
            g.origin[a],
            g.margin
        );
        let end = g.origin[a] + g.dims[a] as f64 * g.cell;
        assert!(end >= hi + 4.0 * g.margin, "axis {a}: end {end} < {hi} + 4·{}", g.margin);
    }
    // "margin = 8·2⁻²³·(M + D) + 10⁻⁶·cell" over the grid's corners.
    let end: [f64; 3] = std::array::from_fn(|a| g.origin[a] + g.dims[a] as f64 * g.cell);
    let big = (0..3).map(|a| g.origin[a].abs().max(end[a].abs())).fold(0.0, f64::max);
    let diag = (0..3).map(|a| (end[a] - g.origin[a]).powi(2)).sum::<f64>().sqrt();
    let want = 8.0 * 2f64.powi(-23) * (big + diag) + 1e-6 * g.cell;
    assert!((g.margin - want).abs() <= 1e-9 * want, "margin {} against the formula's {want}", g.margin);
    // Voxel lists: cells + 1 increasing offsets, ascending triangle numbers, equal to the reader's.
    let cells = g.cells();
    assert_eq!(g.voxo.len(), cells + 1);
    assert_eq!(*g.voxo.last().unwrap() as usize, g.voxt.len());
    for c in 0..cells {
        let t = g.cell_tris(c);
        assert!(t.windows(2).all(|w| w[0] < w[1]) && t.iter().all(|&x| (x as usize) < geo.tris.len()));
        assert_eq!(t, ls.cell_triangles(c), "cell {c}");
    }
    assert_eq!(g.variants & Variants::BINARY, Variants::BINARY, "the fixture asks for every variant");
    // Slots in cell order over exactly the non-empty cells.
    assert_eq!(g.slots.len(), cells);
    let mut next = 0;
    for c in 0..cells {
        if g.cell_tris(c).is_empty() {
            assert_eq!(g.slots[c], 0xFFFF_FFFF);
        } else {
            assert_eq!(g.slots[c], next);
            next += 1;
        }
    }
    assert_eq!(next, g.slots_count);
    // Ranks are the prefix counts of the bits; every (slot, shaft) agrees with the reader.
    let (n, w) = (g.n, g.words());
    assert_eq!(g.bits.len(), g.slots_count as usize * w);
    let mut count = 0u32;
    for (k, (&bits, &rank)) in g.bits.iter().zip(&g.ranks).enumerate() {
        assert_eq!(rank, count, "word {k}");
        count += bits.count_ones();
    }
    assert_eq!(count as u64, g.filled);
    let shafts = 15 * n.pow(4);
    for slot in 0..g.slots_count {
        if shafts % 32 != 0 {
            assert_eq!(g.bits[(slot as usize + 1) * w - 1] >> (shafts % 32), 0, "slot {slot}: unused bits");
        }
        for s in 0..shafts {
            assert_eq!(g.rank(slot, s), ls.rank(slot, s), "slot {slot} shaft {s}");
        }
    }
    // Candidate lists: offsets to the entry count, entries sorted by key lower bound, running
    // maximum, local indices in the cell's list; identical to the reader's.
    assert_eq!(g.cand_offsets.len() as u64, g.filled + 1);
    assert_eq!(*g.cand_offsets.last().unwrap() as u64, g.entries_count);
    for r in 0..g.filled as usize {
        let e = g.entries(r);
        assert_eq!(e, ls.entries(r), "rank {r}");
        let (lo, run) = (|x: u32| (x >> 16) & 0xff, |x: u32| x >> 24);
        assert!(e.windows(2).all(|p| lo(p[0]) <= lo(p[1]) && run(p[0]) <= run(p[1])), "rank {r}: {e:x?}");
    }
    assert_eq!(g.pnmt.len() as u64, 2 * g.filled);
    // LSPI: eight binary16 per filled shaft (front R, G, B, 0, back R, G, B, 0), finite.
    if g.variants & Variants::PREILLUM != 0 {
        assert_eq!(g.preillum.len() as u64, g.filled);
        assert_eq!(g.preillum, ls.preillum);
        for r in &g.preillum {
            assert!(r.iter().all(|&h| spec::half(h).is_finite()) && r[3] == 0 && r[7] == 0, "{r:x?}");
        }
    }

    // Lines through cells: the spec's shaft is filled, lists every triangle the line crosses in
    // the cell, and is the shaft `kiln_format::linespace::index::shaft` names.
    let mut rng = kiln_compiler::raycheck::Rng::new(41);
    let (mut lines, mut hits) = (0, 0);
    let nonempty: Vec<usize> = (0..cells).filter(|&c| !g.cell_tris(c).is_empty()).collect();
    let world = |c0: [f64; 3], l: [f64; 3]| std::array::from_fn::<f64, 3, _>(|a| c0[a] + g.cell * l[a]);
    let tri_f64 = |t: u32| g_tri(geo, t);
    for _ in 0..20_000 {
        let c = nonempty[rng.below(nonempty.len())];
        let (p0, p1): ([f64; 3], [f64; 3]) =
            (std::array::from_fn(|_| rng.f32() as f64), std::array::from_fn(|_| rng.f32() as f64));
        let d: [f64; 3] = std::array::from_fn(|a| p1[a] - p0[a]);
        // Slabs: enter through the face whose slab is entered last, leave through the one left
        // first, ties to the lower axis.
        let (mut tin, mut fin, mut tout, mut fout) = (f64::NEG_INFINITY, 0u32, f64::INFINITY, 0u32);
        for a in 0..3 {
            if d[a] == 0.0 {
                continue;
            }
            let (t0, t1) = ((0.0 - p0[a]) / d[a], (1.0 - p0[a]) / d[a]);
            let (near, far) = (t0.min(t1), t0.max(t1));
            if near > tin {
                tin = near;
                fin = 2 * a as u32 + u32::from(d[a] < 0.0);
            }
            if far < tout {
                tout = far;
                fout = 2 * a as u32 + u32::from(d[a] > 0.0);
            }
        }
        if fin == fout {
            continue;
        }
        let at = |t: f64| std::array::from_fn::<f64, 3, _>(|a| p0[a] + t * d[a]);
        let patch = |face: u32, p: [f64; 3]| {
            let (ua, va) = uv_axes(face);
            let q = |x: f64| ((x.clamp(0.0, 1.0) * n as f64).floor() as u32).min(n - 1);
            q(p[ua]) * n + q(p[va])
        };
        let (pin, pout) = (patch(fin, at(tin)), patch(fout, at(tout)));
        let (a, pa, b, pb) = if fin < fout { (fin, pin, fout, pout) } else { (fout, pout, fin, pin) };
        let shaft = (a * (11 - a) / 2 + b - a - 1) * n.pow(4) + pa * n * n + pb;
        assert_eq!(
            Some((shaft, fin < fout)),
            kiln_format::linespace::index::shaft(fin, pin, fout, pout, n),
            "the spec's shaft numbering and the reader's differ"
        );
        lines += 1;
        let slot = g.slots[c];
        let c0 = g.cell_min(c);
        let (ea, eb) = (world(c0, at(tin)), world(c0, at(tout)));
        for (local, &t) in g.cell_tris(c).iter().enumerate() {
            if !segment_hit(ea, eb, tri_f64(t)).is_some_and(|h| h.3 > 1e-6) {
                continue;
            }
            hits += 1;
            let rank = g.rank(slot, shaft);
            let Some(rank) = rank else {
                panic!("cell {c}: shaft {shaft} empty, but the line crosses triangle {t}")
            };
            assert!(
                g.entries(rank).iter().any(|&e| e & 0xffff == local as u32),
                "cell {c} shaft {shaft}: triangle {t} (local {local}) missing from the candidates"
            );
        }
    }

    // PNMT: where a filled shaft's midpoint segment clearly crosses triangles of its cell, the
    // front record is the first crossing and the back one the last (position, material,
    // interpolated shading normal, uv).
    let mut records = 0;
    for c in 0..cells {
        let slot = g.slots[c];
        if slot == 0xFFFF_FFFF {
            continue;
        }
        let c0 = g.cell_min(c);
        for s in 0..shafts {
            let Some(rank) = g.rank(slot, s) else { continue };
            let (fa, pa, fb, pb) = shaft_parts(s, n);
            let (a, b) = (world(c0, patch_centre(fa, pa, n)), world(c0, patch_centre(fb, pb, n)));
            // Every crossing that might count (within 1e-5 of the triangle and the segment).
            let mut crossings: Vec<(f64, u32, f64, f64, f64)> = g
                .cell_tris(c)
                .iter()
                .filter_map(|&t| segment_hit(a, b, tri_f64(t)).map(|(tt, u, v, m)| (tt, t, u, v, m)))
                .filter(|x| x.4 > -1e-5)
                .collect();
            if crossings.is_empty() {
                continue;
            }
            crossings.sort_by(|x, y| x.0.total_cmp(&y.0));
            let ends = [(0usize, crossings[0]), (1, *crossings.last().unwrap())];
            for (end, (tt, t, u, v, m)) in ends {
                // Crossings near an edge or near another's t are the compiler's f32 test's to
                // decide: skip them.
                if m < 1e-5 || crossings.iter().any(|x| x.1 != t && (x.0 - tt).abs() < 1e-5) {
                    continue;
                }
                let ctx = format!("cell {c} shaft {s} end {end} triangle {t}");
                let (pos, material, got, uv) = pnmt_fields(g.pnmt_layout, &g.pnmt[2 * rank + end])
                    .unwrap_or_else(|| panic!("{ctx}: no record"));
                assert_eq!(material, geo.tmat[t as usize], "{ctx}: material");
                let hit: [f64; 3] = std::array::from_fn(|k| a[k] + tt * (b[k] - a[k]));
                // Half a quantisation step (1/65535 full, 1/1023 compact) beyond the f32 test's
                // reach.
                let step = if g.pnmt_layout == 0 { 0.5 / 65535.0 } else { 0.5 / 1023.0 };
                for k in 0..3 {
                    let got = c0[k] + pos[k] * g.cell;
                    assert!(
                        (got - hit[k]).abs() <= g.cell * (1e-4 + step),
                        "{ctx}: position {k}: {got} against {}",
                        hit[k]
                    );
                }
                let tri = geo.tris[t as usize];
                let w = [1.0 - u - v, u, v];
                let sn: [f64; 3] = std::array::from_fn(|x| {
                    (0..3).map(|k| w[k] * geo.normals[tri[k] as usize][x] as f64).sum()
                });
                let l = (sn[0] * sn[0] + sn[1] * sn[1] + sn[2] * sn[2]).sqrt();
                let cos = (0..3).map(|x| got[x] * sn[x] / l).sum::<f64>();
                // 0.08° full (< 0.005° of quantisation), 0.16° compact (< 0.12°).
                let slack = if g.pnmt_layout == 0 { 1e-6 } else { 4e-6 };
                assert!(cos > 1.0 - slack, "{ctx}: normal {got:?} against {sn:?}");
                if !geo.uvs.is_empty() && g.pnmt_layout != 2 {
                    for (x, &got) in uv.iter().enumerate() {
                        let want: f64 = (0..3).map(|k| w[k] * geo.uvs[tri[k] as usize][x] as f64).sum();
                        assert!((got as f64 - want).abs() <= 2e-3 * want.abs().max(1.0), "{ctx}: uv {x}");
                    }
                } else {
                    assert_eq!(uv, [0.0, 0.0]);
                }
                records += 1;
            }
        }
    }
    (lines, hits, records)
}

fn g_tri(geo: &Geometry, t: u32) -> [[f64; 3]; 3] {
    geo.tris[t as usize].map(|v| geo.positions[v as usize].map(f64::from))
}

/// Reads `bytes` with both readers and compares everything the spec decoder knows; the manifest's
/// inputs are read from the first of `inputs_at` holding them: the scene file's folder, the
/// sidecar's (FORMAT.md: each path is relative to one of them).
fn agree(name: &str, bytes: &[u8], inputs_at: &[&Path]) -> String {
    let f = spec::open(bytes).unwrap_or_else(|e| panic!("{name}: the spec decoder refuses it: {e}"));
    let file = KilnFile::from_bytes(bytes, Checksums::Eager).unwrap();
    assert_eq!(f.version, (file.header().version_major, file.header().version_minor));
    assert_eq!(f.entries.len(), file.sections().len());
    for (e, s) in f.entries.iter().zip(file.sections()) {
        let r = &s.entry;
        let theirs = spec::Entry {
            kind: r.kind.0,
            version: r.version,
            codec: r.codec,
            align_log2: r.align_log2,
            index: r.index,
            flags: r.flags,
            offset: r.offset,
            size: r.size,
            raw_size: r.raw_size,
            checksum: r.checksum,
            content_hash: r.content_hash.0,
        };
        assert_eq!(e, &theirs, "{name}: entry {}", s.position);
    }
    // The manifest, every field.
    let manifest = decode_manifest(f.section(b"MANI", 0).unwrap());
    let theirs = file.manifest().unwrap();
    assert_eq!(manifest, theirs, "{name}: manifest");
    // Input hashes: xxh3_128 of the file, hex of the stored (little-endian) bytes.
    for input in &manifest.inputs {
        let at = inputs_at.iter().map(|d| d.join(&input.path)).find(|p| p.is_file());
        let data =
            std::fs::read(at.unwrap_or_else(|| panic!("{name}: input {} not found", input.path))).unwrap();
        assert_eq!(input.bytes, data.len() as u64);
        assert_eq!(input.hash, spec::hash_hex(&data), "{name}: hash of {}", input.path);
    }
    // Geometry and materials.
    let view = SceneView::new(&file).unwrap();
    let geo = decode_geometry(&f);
    assert_eq!(geo.positions.len(), view.vertices.len());
    for (i, v) in view.vertices.iter().enumerate() {
        assert_eq!((geo.positions[i], geo.normals[i]), (v.position, v.normal), "{name}: vertex {i}");
    }
    assert_eq!(geo.uvs, view.uvs, "{name}: UVS0");
    // COL0: absent (all white) or one unorm16 RGBA per vertex, not all white.
    assert!(geo.colors.is_empty() || geo.colors.len() == geo.positions.len(), "{name}: COL0 length");
    assert!(geo.colors.is_empty() || geo.colors.iter().any(|c| *c != [u16::MAX; 4]), "{name}: white COL0");
    assert_eq!(geo.colors, view.colors, "{name}: COL0");
    assert_eq!(geo.tris, view.triangles, "{name}: TRIS");
    assert_eq!(geo.tmat, view.triangle_materials, "{name}: TMAT");
    // Format 1.9 writes MATL version 3: 112-byte records.
    let matl = f.section(b"MATL", 0).unwrap();
    let matl_entry = f.entries.iter().find(|e| &e.kind == b"MATL").unwrap();
    assert_eq!(matl_entry.version, 3, "{name}: MATL version");
    assert_eq!(matl.len(), 112 * view.materials.len());
    for (i, m) in view.materials.iter().enumerate() {
        let b = &matl[112 * i..112 * i + 112];
        use spec::{f32_at, f32s, u32_at};
        let mine = (
            f32s::<4>(b, 0),
            f32s::<3>(b, 16),
            [f32_at(b, 28), f32_at(b, 32), f32_at(b, 36), f32_at(b, 40), f32_at(b, 44)],
            [u32_at(b, 48), u32_at(b, 52), u32_at(b, 56), u32_at(b, 60), u32_at(b, 64), u32_at(b, 68)],
            [u32_at(b, 72), u32_at(b, 76)],
            [f32_at(b, 80), f32_at(b, 84)],
            [u32_at(b, 88), u32_at(b, 92)],
            (f32_at(b, 96), u32_at(b, 100), [u32_at(b, 104), u32_at(b, 108)]),
        );
        let theirs = (
            m.base_color,
            m.emission,
            [m.metallic, m.roughness, m.alpha_cutoff, m.normal_scale, m.occlusion_strength],
            [
                m.base_color_texture,
                m.metallic_roughness_texture,
                m.normal_texture,
                m.occlusion_texture,
                m.emissive_texture,
                m.flags,
            ],
            // Format 1.7: zero unless flag bit 4 says they hold the dielectric's F0 and F90.
            if m.flags & 16 == 0 { [0, 0] } else { m.specular },
            [m.clearcoat, m.clearcoat_roughness],
            [m.clearcoat_texture, m.clearcoat_roughness_texture],
            // Format 1.9: the transmission, its texture, two reserved zero words.
            (m.transmission, m.transmission_texture, [0, 0]),
        );
        assert_eq!(mine, theirs, "{name}: material {i}");
        if m.flags & 16 != 0 {
            // Four IEEE halves in [0, 1]: sign clear, exponent at most 15 (1.0 = 0x3C00).
            let halves = [mine.4[0] & 0xFFFF, mine.4[0] >> 16, mine.4[1] & 0xFFFF, mine.4[1] >> 16];
            assert!(halves.iter().all(|&h| h <= 0x3C00), "{name}: material {i} F0/F90 halves {halves:x?}");
        }
    }
    // The BVH: node fields at the spec's offsets, then the tree and its boxes.
    let nodes = decode_bvh(&f);
    assert_eq!(nodes.len(), view.bvh.len());
    for (i, (mine, n)) in nodes.iter().zip(view.bvh).enumerate() {
        let theirs = Node {
            p: n.p,
            e: n.e,
            imask: n.imask,
            child_base: n.child_base_idx,
            prim_base: n.primitive_base_idx,
            meta: n.child_meta,
            q: [n.child_min_x, n.child_max_x, n.child_min_y, n.child_max_y, n.child_min_z, n.child_max_z],
        };
        assert_eq!(mine, &theirs, "{name}: node {i}");
    }
    let (mut seen, mut leaves) = (vec![0u32; nodes.len()], vec![0u32; geo.tris.len()]);
    let mut bad = Vec::new();
    if !nodes.is_empty() {
        walk(&nodes, &geo, 0, &mut seen, &mut leaves, &mut bad);
    }
    assert!(seen.iter().all(|&s| s == 1), "{name}: a node is unreachable or shared");
    assert!(leaves.iter().all(|&s| s == 1), "{name}: a triangle is in no leaf or in two");
    assert!(
        bad.is_empty(),
        "{name}: {} child boxes miss their triangles, e.g. {:?}",
        bad.len(),
        &bad[..bad.len().min(3)]
    );
    let mut summary = format!(
        "{name}: {} sections, {} nodes, {} triangles, {} uvs, {} inputs",
        f.entries.len(),
        nodes.len(),
        geo.tris.len(),
        geo.uvs.len(),
        manifest.inputs.len()
    );
    // Lighting bakes and textures: sizes by the spec's rules, contents as the reader's.
    let counts = check_bakes(name, &f, &manifest, &file);
    summary += &format!("; {counts}");
    // The line space.
    let ls = LineSpace::new(&file, view.triangles.len(), view.materials.len()).unwrap();
    match (Grid::decode(&f), ls) {
        (None, None) => {}
        (Some(g), Some(ls)) => {
            let (lines, hits, records) = check_grid(&g, &geo, &manifest, &ls);
            summary += &format!(
                "; grid {:?} N = {}, {} slots, {} filled; {lines} lines ({hits} crossings), {records} PNMT records checked",
                g.dims, g.n, g.slots_count, g.filled
            );
        }
        (mine, theirs) => {
            panic!("{name}: VGRD {} by the spec, {} by the reader", mine.is_some(), theirs.is_some())
        }
    }
    summary
}

/// `TEXL`, `BRDF`, `SHDW` and `MVIS` by FORMAT.md: one section per manifest record, sized by
/// the record (mip chains; N² texels, six N × N faces for cube maps with N = `resolution`; one
/// byte per `dims` cell), each equal to what the reader hands out.
fn check_bakes(name: &str, f: &spec::File, m: &Manifest, file: &KilnFile) -> String {
    use kiln_format::sections::{BRDF_LUT, MEDIA_VISIBILITY, SHADOW_MAP};
    let count = |kind: &[u8; 4]| f.entries.iter().filter(|e| &e.kind == kind).count();
    assert_eq!(count(b"TEXL"), m.textures.len(), "{name}: TEXL sections");
    let mut formats = Vec::new();
    for (i, t) in m.textures.iter().enumerate() {
        let levels = 32 - t.width.max(t.height).leading_zeros();
        assert_eq!(t.mip_levels, levels, "{name}: texture {i} mip levels");
        let e = f.entries.iter().find(|e| &e.kind == b"TEXL" && e.index == i as u32).unwrap();
        let b = f.section(b"TEXL", i as u32).unwrap();
        // Version 1: bare RGBA8. Version 2: a 16-byte header (u32 format: 0 RGBA8, 1 BC7, 2 BC5,
        // 3 BC4; four swizzle bytes 0..=5; eight zero bytes), then the chain, each level
        // ceil(w/4) × ceil(h/4) blocks of 16 bytes (BC7, BC5) or 8 (BC4).
        let (format, swizzle, chain) = match e.version {
            1 => (0u32, [0u8, 1, 2, 3], b),
            2 => {
                assert_eq!(&b[8..16], &[0u8; 8], "{name}: texture {i} reserved bytes");
                (spec::u32_at(b, 0), [b[4], b[5], b[6], b[7]], &b[16..])
            }
            v => panic!("{name}: texture {i} section version {v}"),
        };
        let (block, block_bytes, channels) = match format {
            0 => (1u64, 4u64, 4u8),
            1 => (4, 16, 4),
            2 => (4, 16, 2),
            3 => (4, 8, 1),
            other => panic!("{name}: texture {i} pixel format {other}"),
        };
        assert!(
            swizzle.iter().all(|&c| c == 4 || c == 5 || c < channels),
            "{name}: texture {i} swizzle {swizzle:?}"
        );
        if format >= 2 {
            assert_eq!(
                t.color_space,
                kiln_format::manifest::ColorSpace::Linear,
                "{name}: texture {i} BC4/BC5 sRGB"
            );
        }
        let bytes: u64 = (0..levels)
            .map(|l| {
                let (w, h) = ((t.width >> l).max(1) as u64, (t.height >> l).max(1) as u64);
                w.div_ceil(block) * h.div_ceil(block) * block_bytes
            })
            .sum();
        assert_eq!(chain.len() as u64, bytes, "{name}: texture {i} bytes");
        let view = SceneView::new(file).unwrap();
        let theirs = view.texture(i).unwrap();
        assert_eq!(
            (format, swizzle, chain),
            (theirs.format as u32, theirs.swizzle.map(|c| c as u8), theirs.levels),
            "{name}: texture {i}"
        );
        formats.push(format);
    }
    match (&m.brdf_lut, f.section(b"BRDF", 0)) {
        (Some(lut), Some(b)) => {
            assert_eq!(b.len(), 4 * (lut.resolution * lut.resolution) as usize, "{name}: BRDF bytes");
            assert_eq!(spec::u32s(b), file.pod::<u32>(BRDF_LUT, 0).unwrap().unwrap());
        }
        (None, None) => {}
        (lut, b) => panic!("{name}: brdf_lut {lut:?} with BRDF section {}", b.is_some()),
    }
    assert_eq!(count(b"SHDW"), m.shadow_maps.len(), "{name}: SHDW sections");
    for (i, s) in m.shadow_maps.iter().enumerate() {
        let faces = if s.projection == ShadowProjection::Cube { 6 } else { 1 };
        let b = f.section(b"SHDW", i as u32).unwrap();
        assert_eq!(
            b.len(),
            4 * faces * (s.resolution * s.resolution) as usize,
            "{name}: shadow map {i} bytes"
        );
        let depths: Vec<f32> = (0..b.len() / 4).map(|k| spec::f32_at(b, 4 * k)).collect();
        assert_eq!(depths, file.pod::<f32>(SHADOW_MAP, i as u32).unwrap().unwrap(), "{name}: shadow map {i}");
        assert!(depths.iter().all(|d| d.is_finite() && *d >= 0.0), "{name}: shadow map {i} depths");
        if s.projection == ShadowProjection::Cube {
            assert_eq!(s.view_proj, glam::Mat4::IDENTITY.to_cols_array(), "{name}: cube map {i} view_proj");
            assert_eq!(s.near, 0.0);
        }
    }
    let mut volumes = 0;
    if let Some(v) = &m.media_visibility {
        assert_eq!(count(b"MVIS"), v.lights.len(), "{name}: MVIS sections");
        for i in 0..v.lights.len() as u32 {
            let b = f.section(b"MVIS", i).unwrap();
            assert_eq!(b.len(), v.dims.iter().product::<u32>() as usize, "{name}: volume {i} bytes");
            assert_eq!(b, file.pod::<u8>(MEDIA_VISIBILITY, i).unwrap().unwrap());
            volumes += 1;
        }
    } else {
        assert_eq!(count(b"MVIS"), 0);
    }
    // EMLU: one f32 per triangle, finite and non-negative, 0 where the material emits nothing.
    let emlu =
        f.section(b"EMLU", 0).map(|b| (0..b.len() / 4).map(|k| spec::f32_at(b, 4 * k)).collect::<Vec<f32>>());
    if let Some(l) = &emlu {
        let view = SceneView::new(file).unwrap();
        assert_eq!(l.len(), view.triangles.len(), "{name}: EMLU values");
        for (t, (&v, &mat)) in l.iter().zip(view.triangle_materials).enumerate() {
            assert!(v.is_finite() && v >= 0.0, "{name}: EMLU {t} is {v}");
            if view.materials[mat as usize].emission == [0.0; 3] {
                assert_eq!(v, 0.0, "{name}: EMLU {t} of a material that emits nothing");
            }
        }
        assert_eq!(Some(l.as_slice()), view.emitter_luminance().unwrap(), "{name}: EMLU");
    }
    // The probe volume: the header's layout sizes the states and both atlases; states are on or
    // off within half a spacing; E5B9G9R9 texels decode to finite values; distance moments are
    // finite and non-negative binary16.
    let probes = f.section(b"PRBG", 0).map(|h| {
        assert_eq!(h.len(), 64, "{name}: PRBG bytes");
        let u = |i: usize| spec::u32_at(h, 4 * i);
        let spacing = spec::f32_at(h, 12);
        let dims = [u(4), u(5), u(6)];
        let (ti, tv, layers, active) = (u(7), u(8), u(9), u(13));
        let probes = dims.iter().product::<u32>() as usize;
        let states = f.section(b"PRBS", 0).unwrap();
        assert_eq!(states.len(), 16 * probes, "{name}: PRBS bytes");
        let on = (0..probes)
            .filter(|&p| {
                let w = spec::f32_at(states, 16 * p + 12);
                assert!(w == 0.0 || w == 1.0, "{name}: probe {p} state {w}");
                for a in 0..3 {
                    assert!(spec::f32_at(states, 16 * p + 4 * a).abs() <= 0.5 * spacing * 1.001);
                }
                w == 1.0
            })
            .count();
        assert_eq!(on as u32, active, "{name}: probes on");
        let atlas = |t: u32, l: u32| ((dims[0] * (t + 2)) * (dims[1] * (t + 2)) * dims[2] * l) as usize;
        let irr = f.section(b"PRBI", 0).unwrap();
        assert_eq!(irr.len(), 4 * atlas(ti, layers), "{name}: PRBI bytes");
        for k in 0..irr.len() / 4 {
            let t = spec::u32_at(irr, 4 * k);
            let scale = 2f32.powi((t >> 27) as i32 - 24);
            assert!(((t & 511) as f32 * scale).is_finite());
        }
        let vis = f.section(b"PRBV", 0).unwrap();
        assert_eq!(vis.len(), 4 * atlas(tv, 1), "{name}: PRBV bytes");
        for k in 0..vis.len() / 2 {
            let bits = u16::from_le_bytes([vis[2 * k], vis[2 * k + 1]]);
            // binary16: sign clear, exponent not all ones.
            assert!(bits & 0x8000 == 0 || bits == 0x8000, "{name}: PRBV value {k} negative");
            assert_ne!(bits & 0x7c00, 0x7c00, "{name}: PRBV value {k} not finite");
        }
        probes
    });
    // The environment: the header's map, levels and table size the other three sections; the
    // direction of a texel follows the mapping (u = atan2(x, -z) / 2pi, v = acos(y) / pi), and
    // the table's cells are an alias table whose densities integrate to 1 over the sphere.
    let environment = f.section(b"ENVH", 0).map(|h| {
        assert_eq!(h.len(), 192, "{name}: ENVH bytes");
        let u = |i: usize| spec::u32_at(h, 4 * i);
        let (w, hh) = (u(0), u(1));
        assert_eq!(w, 2 * hh, "{name}: the map is twice as wide as tall");
        let (fw, levels, first, tw, th) = (u(4), u(6), u(7), u(8), u(9));
        assert_eq!(first, w * hh, "{name}: level 0 starts after the map's texels");
        let level_texels: u32 = (0..levels).map(|l| (fw >> l).max(2) * ((fw >> l).max(2) / 2)).sum();
        assert_eq!(f.section(b"ENVR", 0).unwrap().len(), 4 * (w * hh) as usize, "{name}: ENVR bytes");
        assert_eq!(f.section(b"ENVP", 0).unwrap().len(), 4 * level_texels as usize, "{name}: ENVP bytes");
        let cells = f.section(b"ENVT", 0).unwrap();
        assert_eq!(cells.len(), 16 * (tw * th) as usize, "{name}: ENVT bytes");
        let mut total = 0.0f64;
        for c in 0..(tw * th) as usize {
            let (keep, alias, density) = (
                spec::f32_at(cells, 16 * c),
                spec::u32_at(cells, 16 * c + 4),
                spec::f32_at(cells, 16 * c + 8),
            );
            assert!((0.0..=1.0).contains(&keep) && alias < tw * th && density >= 0.0, "{name}: cell {c}");
            assert_eq!(spec::f32_at(cells, 16 * c + 12), spec::f32_at(cells, 16 * alias as usize + 8));
            // density / sin θ over the cell's solid angle (sin θ dθ dφ): density · (π/th)(2π/tw).
            total +=
                density as f64 * std::f64::consts::PI / th as f64 * 2.0 * std::f64::consts::PI / tw as f64;
        }
        assert!((total - 1.0).abs() < 1e-3, "{name}: the table's density integrates to {total}");
        let env = kiln_format::environment::Environment::read(file).unwrap().expect("the reference reads it");
        assert_eq!(bytemuck::cast_slice::<u32, u8>(env.map), f.section(b"ENVR", 0).unwrap(), "{name}: ENVR");
        for (x, y) in [(0, 0), (w - 1, hh / 2), (w / 3, hh - 1)] {
            let (phi, theta) = (
                2.0 * std::f32::consts::PI * (x as f32 + 0.5) / w as f32,
                std::f32::consts::PI * (y as f32 + 0.5) / hh as f32,
            );
            let d = glam::Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos());
            let t = spec::u32_at(f.section(b"ENVR", 0).unwrap(), 4 * (y * w + x) as usize);
            let scale = 2f32.powi((t >> 27) as i32 - 24);
            let texel =
                glam::Vec3::new((t & 511) as f32, ((t >> 9) & 511) as f32, ((t >> 18) & 511) as f32) * scale;
            assert_eq!(env.radiance(d), texel, "{name}: the texel of direction {d} ({x}, {y})");
        }
        w
    });
    format!(
        "{} textures (formats {formats:?}), BRDF {}, {} shadow maps, {volumes} visibility volumes, EMLU {}, {} probes, \
         environment {}",
        m.textures.len(),
        m.brdf_lut.is_some(),
        m.shadow_maps.len(),
        emlu.is_some(),
        probes.unwrap_or(0),
        environment.unwrap_or(0)
    )
}

/// The demo Cornell box with a textured material (so `UVS0` is written), vertex colours (`COL0`),
/// a spot light, every line-space variant at N = 3.
fn fixture() -> Vec<u8> {
    fixture_with(Codec::Auto)
}

/// The fixture, its sections compressed as `codec` says.
fn fixture_with(codec: Codec) -> Vec<u8> {
    let mut s = cornell_box();
    s.textures.push(Texture {
        name: "checker".into(),
        width: 4,
        height: 4,
        rgba: (0..64u32).map(|i| (i * 4) as u8).collect(),
        role: TextureRole::Color,
        wrap_u: Wrap::MirroredRepeat,
        wrap_v: Wrap::ClampToEdge,
        mag_linear: false,
    });
    s.materials[0].gpu.base_color_texture = 0;
    // A normal map (BC5) and an occlusion map (BC4), sized to leave partial blocks.
    s.textures.push(Texture {
        name: "bumps".into(),
        width: 6,
        height: 5,
        rgba: (0..30u32).flat_map(|i| [(100 + i * 3) as u8, (140 - i * 2) as u8, 240, 255]).collect(),
        role: TextureRole::Normal,
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        mag_linear: true,
    });
    s.textures.push(Texture {
        name: "occlusion".into(),
        width: 9,
        height: 3,
        rgba: (0..27u32).flat_map(|i| [(i * 9) as u8, 0, 0, 255]).collect(),
        role: TextureRole::Data,
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        mag_linear: true,
    });
    s.materials[0].gpu.normal_texture = 1;
    s.materials[0].gpu.occlusion_texture = 2;
    // Emission through the checker, so that EMLU is written.
    s.materials[0].gpu.emission = [0.5, 0.25, 0.125];
    s.materials[0].gpu.emissive_texture = 0;
    for (i, uv) in s.uvs.iter_mut().enumerate() {
        *uv = [(i % 7) as f32 * 0.37 - 0.5, (i % 5) as f32 * 1.3];
    }
    // A second camera, orthographic, so that manifest version 2's list is not empty.
    let mut ortho = s.cameras[0].clone();
    ortho.name = "ortho".into();
    s.cameras.push(ortho);
    s.orthographic.push(OrthographicCamera { camera: 1, xmag: 1.25, ymag: 0.75 });
    // Stored relative to an origin far out, so that manifest version 3's origin is not zero.
    s.origin = [1.0e5, -0.25, 3.0e6];
    // Vertex colours, so that COL0 is written.
    let colors = (0..s.vertices.len()).map(|i| [(i * 977 % 65536) as u16, 0, u16::MAX, 40000]).collect();
    s.set_colors(0, Some(colors));
    let mut spot = s.lights[0].clone();
    spot.name = "spot".into();
    spot.kind = LightKind::Spot { inner_cone: 0.3, outer_cone: 0.5 };
    spot.position = [0.3, 1.9, 0.5];
    s.lights.push(spot);
    // An environment of 32 x 16 texels, so that ENVH, ENVR, ENVP and ENVT are written.
    s.environment = Some(kiln_compiler::ir::EnvironmentImage {
        name: "gradient".into(),
        width: 32,
        height: 16,
        pixels: (0..512).map(|i| [0.05 * (i % 32) as f32, 0.5, 0.1 + 0.05 * (i / 32) as f32]).collect(),
        rotation_degrees: 0.0,
    });
    s.media.push(kiln_format::manifest::Medium {
        bounds: Bounds { min: [-0.9, 0.1, -0.9], max: [0.9, 1.3, 0.9] },
        sigma_a: [0.05; 3],
        sigma_s: [0.2; 3],
        g: 0.3,
    });
    let metal = &mut s.materials[1].gpu;
    metal.flags &= !kiln_format::sections::MaterialFlags::DIFFUSE_ONLY;
    metal.metallic = 1.0;
    metal.roughness = 0.4;
    metal.clearcoat = 0.5;
    metal.clearcoat_roughness = 0.25;
    metal.clearcoat_texture = 0;
    metal.transmission = 0.3;
    metal.transmission_texture = 0;
    let settings = Settings {
        voxel_res: VoxelRes::Cells(5),
        shaft_res: Some(3),
        shaft_variants: Some(Variants::ALL),
        shadow_res: 16,
        media_volume_res: 8,
        codec,
        ..Default::default()
    };
    compile_to_bytes(s, settings, "spec-reader").expect("the fixture compiles")
}

#[test]
fn a_reader_written_from_format_md_agrees_with_the_reference_reader() {
    // The hash the spec's example names, so the library below computes standard XXH3-128.
    assert_eq!(spec::hash_hex(b"kiln"), "517e62508817fb5b976f7af3aff6e429");
    assert_eq!(spec::hash_hex(b""), "7f498d4624c30160d8984701d306aa99");
    let bytes = fixture();
    let summary = agree("fixture", &bytes, &[]);
    // Every kind the format knows is here (and so read above): a new kind fails this until the
    // fixture writes it and this reader decodes it.
    let f = spec::open(&bytes).unwrap();
    let mut kinds: Vec<[u8; 4]> = f.entries.iter().map(|e| e.kind).collect();
    let mut known: Vec<[u8; 4]> = kiln_format::sections::KNOWN.iter().map(|k| k.kind.0).collect();
    kinds.sort();
    kinds.dedup();
    known.sort();
    assert_eq!(kinds, known, "the fixture's kinds against sections::KNOWN");
    eprintln!("{summary}");
    assert!(summary.contains("grid") && !summary.contains(" 0 uvs"), "{summary}");
    // It refuses what the spec refuses: a flipped byte of the header, the table, a section,
    // padding, the last byte.
    let pad = f
        .entries
        .windows(2)
        .find(|w| w[0].offset + w[0].size < w[1].offset)
        .map(|w| (w[0].offset + w[0].size) as usize);
    for at in [20usize, 64 + 7, 64 + 16, f.entries[1].offset as usize, pad.unwrap(), bytes.len() - 1] {
        let mut bad = bytes.clone();
        bad[at] ^= 0x40;
        assert!(spec::open(&bad).is_err(), "byte {at} flipped was accepted");
    }
}

#[test]
fn a_reader_written_from_format_md_decodes_zstd_sections() {
    // Every kind compressed (--codec zstd): both readers agree on everything, and the spec
    // decoder's decoded sections equal the stored bytes of the same fixture written uncompressed
    // (the manifest aside: it records the codec setting).
    let zstd = fixture_with(Codec::Zstd);
    let plain = fixture_with(Codec::None);
    let z = spec::open(&zstd).unwrap_or_else(|e| panic!("the spec decoder refuses the zstd file: {e}"));
    let p = spec::open(&plain).unwrap();
    assert!(p.entries.iter().all(|e| e.codec == 0));
    let mut compressed_kinds: Vec<[u8; 4]> =
        z.entries.iter().filter(|e| e.codec == 1).map(|e| e.kind).collect();
    compressed_kinds.dedup();
    // Sections too small or too random for zstd to shrink stay codec 0; most kinds shrink.
    assert!(compressed_kinds.len() * 3 >= kiln_format::sections::KNOWN.len() * 2, "{compressed_kinds:?}");
    assert_eq!(z.entries.len(), p.entries.len());
    for (ze, pe) in z.entries.iter().zip(&p.entries) {
        assert_eq!((ze.kind, ze.index), (pe.kind, pe.index));
        assert_eq!(ze.raw_size, pe.size);
        if ze.codec == 1 {
            assert!(ze.size < ze.raw_size, "a frame kept though not smaller");
        }
        if &ze.kind != b"MANI" {
            assert_eq!(z.section(&ze.kind, ze.index), p.section(&pe.kind, pe.index), "{:?}", ze.kind);
        }
    }
    let summary = agree("fixture, zstd", &zstd, &[]);
    eprintln!("{summary}");
    // The frame rules: a frame cut short, a byte after it, a different declared size are refused.
    let e = z.entries.iter().find(|e| e.codec == 1 && e.size > 16).unwrap();
    let frame = &zstd[e.offset as usize..(e.offset + e.size) as usize];
    assert!(spec::decode_zstd(frame, e.raw_size).is_ok());
    assert!(spec::decode_zstd(&frame[..frame.len() - 1], e.raw_size).is_err());
    assert!(spec::decode_zstd(&[frame, &[0]].concat(), e.raw_size).is_err());
    assert!(spec::decode_zstd(frame, e.raw_size + 1).is_err());
    assert!(spec::decode_zstd(frame, e.raw_size - 1).is_err());
}

/// The shared scenes, compiled by `kiln compile` with their sidecars (so the manifest records
/// input files and hashes) and a small line space.
#[test]
fn a_reader_written_from_format_md_agrees_on_the_shared_scenes() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes");
    let dir = tempfile::tempdir().unwrap();
    for (name, extra) in [
        (
            "cornell_box",
            &["--voxel-res", "6", "--shaft-res", "2", "--shaft-variants", "binary,candidates,pnmt,preillum"]
                [..],
        ),
        ("pica_pica", &["--shaft-variants", "none"][..]),
    ] {
        let input = root.join(name).join("scene.gltf");
        if !input.is_file() {
            eprintln!("skipped: {} is absent", input.display());
            continue;
        }
        let side =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/scenes").join(format!("{name}.toml"));
        let out = dir.path().join(format!("{name}.kiln"));
        let args = [
            "compile",
            input.to_str().unwrap(),
            "--config",
            side.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
        ];
        run::kiln(dir.path(), &args.iter().copied().chain(extra.iter().copied()).collect::<Vec<_>>())
            .expect(0);
        let bytes = std::fs::read(&out).unwrap();
        let summary = agree(name, &bytes, &[input.parent().unwrap(), side.parent().unwrap()]);
        // `kiln inspect --json` prints each content hash as hex of its stored bytes, in order.
        let run = run::kiln(dir.path(), &["inspect", out.to_str().unwrap(), "--json"]);
        run.expect(0);
        let j: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
        let entries = spec::open(&bytes).unwrap().entries;
        assert_eq!(j["sections"].as_array().unwrap().len(), entries.len());
        for (e, js) in entries.iter().zip(j["sections"].as_array().unwrap()) {
            let hex: String = e.content_hash.iter().map(|b| format!("{b:02x}")).collect();
            assert_eq!(js["content_hash"], hex, "{name}: {}", js["kind"]);
            assert_eq!(js["checksum"], format!("{:016x}", e.checksum), "{name}: {}", js["kind"]);
        }
        eprintln!("{summary}");
        assert!(!summary.contains(" 0 inputs"), "{summary}");
        assert!(name != "pica_pica" || !summary.contains(" 0 uvs"), "{summary}");
    }
}
