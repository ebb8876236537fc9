//! Damaged files: `kiln verify` on hundreds of randomly damaged copies of a real file (every one
//! exits non-zero with one line of error, none panics), and a fixture holding every section kind
//! the format knows, damaged section by section: the checksum of each is checked and the error
//! names it; hostile content under good checksums never panics.

#[path = "util/run.rs"]
mod run;

use std::collections::BTreeSet;

use kiln_compiler::import::demo::cornell_box;
use kiln_compiler::ir::{Texture, TextureRole};
use kiln_compiler::pipeline::compile_to_bytes;
use kiln_compiler::settings::{BRDF_LUT_RES, MEDIA_VOLUME_RES, SHADOW_RES, Settings, VoxelRes};
use kiln_format::checksum::checksum64;
use kiln_format::header::{HEADER_SIZE, Header};
use kiln_format::linespace::Variants;
use kiln_format::manifest::{Bounds, LightKind, Medium, ShadowProjection, Wrap};
use kiln_format::sections::{self, MaterialFlags};
use kiln_format::table::ENTRY_SIZE;
use kiln_format::{Checksums, KilnFile, SectionEntry, SectionKind};
use run::kiln;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

#[test]
fn randomly_damaged_copies_are_all_refused() {
    let dir = tempfile::tempdir().unwrap();
    kiln(dir.path(), &["demo", "-o", "good.kiln", "-q"]).expect(0);
    let good = std::fs::read(dir.path().join("good.kiln")).unwrap();
    let mut rng = Rng(42);
    for case in 0..300 {
        let mut bad = good.clone();
        match case % 4 {
            0 => {
                let i = rng.below(bad.len());
                bad[i] ^= 1 << rng.below(8);
            }
            1 => bad.truncate(rng.below(good.len())),
            2 => {
                let start = rng.below(bad.len());
                let end = (start + 1 + rng.below(64)).min(bad.len());
                for b in &mut bad[start..end] {
                    *b = rng.next() as u8;
                }
                if bad == good {
                    bad[start] ^= 0xff;
                }
            }
            _ => {
                let i = rng.below(bad.len());
                bad.insert(i, rng.next() as u8);
            }
        }
        let name = format!("bad{case}.kiln");
        std::fs::write(dir.path().join(&name), &bad).unwrap();
        let run = kiln(dir.path(), &["verify", &name]);
        assert!(run.code == 1 || run.code == 3, "case {case}: {run:?}");
        assert!(!run.stderr.contains("panicked"), "case {case}: {run:?}");
        assert_eq!(run.stderr.lines().count(), 1, "case {case}: {run:?}");
        run.says("error: ");
        assert!(run.stdout.is_empty(), "case {case}: a refused file printed a report: {run:?}");
        std::fs::remove_file(dir.path().join(&name)).unwrap();
    }
}

// ---------------------------------------------------------------- every section kind

/// The demo box made to need every section kind the compiler writes: a texture on the white
/// material, a rough metal (so the BRDF table is baked), the rect light (cube shadow map) plus a
/// spot light (2D shadow map), a medium (visibility volume per light), and all four line-space
/// variants, everything at its smallest resolution so that the file stays small.
fn every_kind_file() -> Vec<u8> {
    let mut s = cornell_box();
    s.textures.push(Texture {
        name: "checker".into(),
        width: 4,
        height: 4,
        rgba: (0..64u32).map(|i| (i * 4) as u8).collect(),
        role: TextureRole::Color,
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        mag_linear: true,
    });
    s.materials[0].gpu.base_color_texture = 0;
    let metal = &mut s.materials[1].gpu;
    metal.flags &= !MaterialFlags::DIFFUSE_ONLY;
    metal.metallic = 1.0;
    metal.roughness = 0.4;
    let mut spot = s.lights[0].clone();
    spot.name = "spot".into();
    spot.kind = LightKind::Spot { inner_cone: 0.3, outer_cone: 0.5 };
    spot.position = [0.3, 1.9, 0.5];
    s.lights.push(spot);
    s.media.push(Medium {
        bounds: Bounds { min: [-0.9, 0.1, -0.9], max: [0.9, 1.8, 0.9] },
        sigma_a: [0.05; 3],
        sigma_s: [0.2; 3],
        g: 0.3,
    });
    let settings = Settings {
        voxel_res: VoxelRes::Cells(4),
        shaft_res: Some(1),
        shaft_variants: Some(Variants::ALL),
        brdf_lut_res: BRDF_LUT_RES.min,
        shadow_res: SHADOW_RES.min,
        media_volume_res: MEDIA_VOLUME_RES.min,
        ..Default::default()
    };
    compile_to_bytes(s, settings, "every-kind").expect("the fixture compiles")
}

#[test]
fn the_every_kind_fixture_holds_every_kind_the_format_knows() {
    // Fails when a kind is added to the format's list without the fixture producing it: the
    // damage tests below would then never see it.
    let bytes = every_kind_file();
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let present: BTreeSet<String> = file.sections().iter().map(|s| s.entry.kind.name()).collect();
    let known: BTreeSet<String> = sections::KNOWN.iter().map(|k| k.kind.name()).collect();
    let missing: Vec<_> = known.difference(&present).collect();
    assert!(missing.is_empty(), "the every-kind fixture lacks {missing:?}: extend every_kind_file()");
    assert!(file.skipped().next().is_none(), "the fixture holds kinds the reader skips");
    // Both shadow-map shapes, and a visibility volume for each light.
    let manifest = file.manifest().unwrap();
    let projections: Vec<_> = manifest.shadow_maps.iter().map(|m| m.projection).collect();
    assert!(projections.contains(&ShadowProjection::Cube), "{projections:?}");
    assert!(projections.contains(&ShadowProjection::Perspective), "{projections:?}");
    assert_eq!(file.all_of(sections::SHADOW_MAP).len(), manifest.shadow_maps.len());
    assert_eq!(file.all_of(sections::MEDIA_VISIBILITY).len(), manifest.lights.len());
    // Each section has bytes to damage.
    for s in file.sections() {
        assert!(s.entry.size > 0, "section {}#{} is empty", s.entry.kind, s.entry.index);
    }
    assert!(bytes.len() < 256 << 10, "the fixture grew to {} bytes", bytes.len());
}

/// The sections of `bytes` as (kind, index, offset, size).
fn section_spans(bytes: &[u8]) -> Vec<(SectionKind, u32, usize, usize)> {
    let file = KilnFile::from_bytes(bytes, Checksums::Eager).unwrap();
    file.sections()
        .iter()
        .map(|s| (s.entry.kind, s.entry.index, s.entry.offset as usize, s.entry.size as usize))
        .collect()
}

#[test]
fn damage_inside_every_section_is_refused_naming_the_section() {
    let good = every_kind_file();
    for (position, (kind, index, offset, size)) in section_spans(&good).into_iter().enumerate() {
        let name = format!("({kind}#{index})");
        for at in [offset, offset + size / 2, offset + size - 1] {
            let mut bad = good.clone();
            bad[at] ^= 0x10;
            // Opening with every checksum checked fails on this section.
            let msg = match KilnFile::from_bytes(&bad, Checksums::Eager) {
                Ok(_) => panic!("{name}: damage at byte {at} was accepted"),
                Err(e) => e.to_string(),
            };
            assert!(msg.contains(&name) && msg.contains("checksum mismatch"), "{name} byte {at}: {msg}");
            // Deferred to access: the layout opens, this section alone is refused when read.
            let file = KilnFile::from_bytes(&bad, Checksums::OnAccess).expect("layout intact");
            for s in file.sections() {
                let read = file.section_bytes(s);
                assert_eq!(
                    read.is_err(),
                    s.position == position,
                    "{name} damaged, {}#{} read",
                    s.entry.kind,
                    s.entry.index
                );
            }
            let msg = file.section_bytes(&file.sections()[position]).unwrap_err().to_string();
            assert!(msg.contains(&name), "{name}: {msg}");
        }
    }
}

#[test]
fn kiln_verify_refuses_damage_in_every_section_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let good = every_kind_file();
    for (kind, index, offset, size) in section_spans(&good) {
        let mut bad = good.clone();
        bad[offset + size / 2] ^= 0x01;
        std::fs::write(dir.path().join("bad.kiln"), &bad).unwrap();
        let run = kiln(dir.path(), &["verify", "bad.kiln"]);
        assert_eq!(run.code, 1, "{kind}#{index} damaged: {run:?}");
        run.expect(1).says(&format!("({kind}#{index})")).says("checksum mismatch");
    }
    std::fs::write(dir.path().join("good.kiln"), &good).unwrap();
    kiln(dir.path(), &["verify", "good.kiln", "--rays", "64"]).expect(0);
}

/// `bytes` with section `position` overwritten by `fill` and every checksum made right again,
/// so that only the content is hostile.
fn rechecksummed(bytes: &[u8], position: usize, fill: u8) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let mut header = Header::parse(&out).unwrap();
    let table = header.table_offset as usize;
    let at = table + position * ENTRY_SIZE;
    let mut entry = SectionEntry::from_bytes(&out[at..at + ENTRY_SIZE]);
    let (o, n) = (entry.offset as usize, entry.size as usize);
    out[o..o + n].fill(fill);
    entry.checksum = checksum64(&out[o..o + n]);
    out[at..at + ENTRY_SIZE].copy_from_slice(&entry.to_bytes());
    let end = table + header.section_count as usize * ENTRY_SIZE;
    header.table_checksum = checksum64(&out[table..end]);
    out[..HEADER_SIZE].copy_from_slice(&header.to_bytes());
    out
}

#[test]
fn hostile_content_with_good_checksums_in_every_section_never_panics() {
    // Every section in turn filled with 0x00 or 0xff under correct checksums: `kiln verify` (with
    // rays through the BVH and the line space) exits with a one-line error or accepts, never
    // panics. Sections that hold indices or counts must be refused.
    let dir = tempfile::tempdir().unwrap();
    let good = every_kind_file();
    let structural = [
        sections::MANIFEST,
        sections::TRIANGLES,
        sections::BVH_NODES,
        sections::GRID,
        sections::VOXEL_OFFSETS,
        sections::SHAFT_SLOTS,
        sections::CANDIDATE_OFFSETS,
    ];
    for (position, (kind, index, _, _)) in section_spans(&good).into_iter().enumerate() {
        for fill in [0x00u8, 0xff] {
            let bad = rechecksummed(&good, position, fill);
            KilnFile::from_bytes(&bad, Checksums::Eager).expect("checksums are right");
            std::fs::write(dir.path().join("bad.kiln"), &bad).unwrap();
            let run = kiln(dir.path(), &["verify", "bad.kiln", "--rays", "64"]);
            let what = format!("{kind}#{index} filled with {fill:#04x}");
            assert!(!run.stderr.contains("panicked") && run.code != 70, "{what}: {run:?}");
            assert!(matches!(run.code, 0 | 1 | 3), "{what}: {run:?}");
            if run.code != 0 {
                assert_eq!(run.stderr.lines().count(), 1, "{what}: {run:?}");
            }
            if fill == 0xff && structural.contains(&kind) {
                assert_ne!(run.code, 0, "{what} was accepted: {run:?}");
            }
        }
    }
}

// ---------------------------------------------------------------- a second decoder

/// A minimal decoder of the header, the section table and the manifest's first fields, written
/// from FORMAT.md's tables alone (not from `kiln-format`), so that the spec and the reference
/// reader cannot drift apart silently: it checks every header and table rule the spec states and
/// must agree, entry by entry, with `KilnFile::sections()`.
mod spec_decoder {
    use xxhash_rust::xxh3::xxh3_64;

    /// One table entry as FORMAT.md lays it out.
    #[derive(Debug, PartialEq, Eq)]
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

    fn u16_at(b: &[u8], o: usize) -> u16 {
        u16::from_le_bytes(b[o..o + 2].try_into().unwrap())
    }
    fn u32_at(b: &[u8], o: usize) -> u32 {
        u32::from_le_bytes(b[o..o + 4].try_into().unwrap())
    }
    fn u64_at(b: &[u8], o: usize) -> u64 {
        u64::from_le_bytes(b[o..o + 8].try_into().unwrap())
    }

    /// Header, table, placement and checksums; `Err` names the first rule broken.
    pub fn decode(b: &[u8]) -> Result<Vec<Entry>, String> {
        if b.len() < 64 || b[0..8] != [0x89, b'K', b'L', b'N', 0x0D, 0x0A, 0x1A, 0x0A] {
            return Err("magic".into());
        }
        if u16_at(b, 8) != 1 {
            return Err("major version".into());
        }
        if xxh3_64(&b[0..56]) != u64_at(b, 56) {
            return Err("header checksum".into());
        }
        let flags = u32_at(b, 12);
        if flags & 0xFFFF != 0 {
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
            if entry.codec != 0 || entry.raw_size != entry.size {
                return Err("codec".into());
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
        Ok(entries)
    }

    /// A bincode varint (FORMAT.md, `MANI`) at `*at`.
    fn varint(b: &[u8], at: &mut usize) -> u64 {
        let tag = b[*at];
        *at += 1;
        let width = match tag {
            0..=250 => return tag as u64,
            251 => 2,
            252 => 4,
            253 => 8,
            _ => panic!("varint tag {tag}"),
        };
        let mut v = [0u8; 8];
        v[..width].copy_from_slice(&b[*at..*at + width]);
        *at += width;
        u64::from_le_bytes(v)
    }

    /// The manifest's first two fields, `generator` and `scene_name`.
    pub fn manifest_names(manifest: &[u8]) -> (String, String) {
        let mut at = 0;
        let mut string = || {
            let n = varint(manifest, &mut at) as usize;
            at += n;
            String::from_utf8(manifest[at - n..at].to_vec()).unwrap()
        };
        (string(), string())
    }
}

#[test]
fn a_decoder_written_from_format_md_agrees_with_the_reference_reader() {
    let bytes = every_kind_file();
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let entries = spec_decoder::decode(&bytes).unwrap();
    assert_eq!(entries.len(), file.sections().len());
    for (e, s) in entries.iter().zip(file.sections()) {
        let r = &s.entry;
        let theirs = spec_decoder::Entry {
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
        assert_eq!(e, &theirs, "entry {}", s.position);
    }
    let mani = entries.iter().find(|e| &e.kind == b"MANI").unwrap();
    let m = file.manifest().unwrap();
    let names =
        spec_decoder::manifest_names(&bytes[mani.offset as usize..(mani.offset + mani.size) as usize]);
    assert_eq!(names, (m.generator.clone(), m.scene_name.clone()));
    // And it refuses what the spec refuses: a flipped byte of the table, of a section, of padding.
    for at in [20usize, 64 + 7, 64 + 16, entries[1].offset as usize, bytes.len() - 1] {
        let mut bad = bytes.clone();
        bad[at] ^= 0x40;
        assert!(spec_decoder::decode(&bad).is_err(), "byte {at} flipped was accepted");
    }
}
