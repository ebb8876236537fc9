//! Hostile files: consistent checksums around impossible layouts. Each must give a clear error.

mod common;

use kiln_format::checksum::checksum64;
use kiln_format::header::{HEADER_SIZE, Header, VERSION_MAJOR};
use kiln_format::table::{ENTRY_SIZE, SectionEntry, SectionKind};
use kiln_format::{Checksums, ContentHash, KilnFile, sections};

/// A file from a table and a body; checksums of header, table and sections are made right so
/// that only the layout is wrong.
fn craft(mut entries: Vec<SectionEntry>, body: &[u8], declared_len: Option<u64>) -> Vec<u8> {
    let table_end = HEADER_SIZE + ENTRY_SIZE * entries.len();
    let mut file = vec![0u8; table_end];
    file.extend_from_slice(body);
    for e in &mut entries {
        let (o, s) = (e.offset as usize, e.size as usize);
        if o <= file.len() && o.saturating_add(s) <= file.len() {
            e.checksum = checksum64(&file[o..o + s]);
        }
    }
    let table: Vec<u8> = entries.iter().flat_map(|e| e.to_bytes()).collect();
    file[HEADER_SIZE..table_end].copy_from_slice(&table);
    let header = Header {
        version_major: VERSION_MAJOR,
        version_minor: 0,
        flags: 0,
        section_count: entries.len() as u32,
        table_offset: HEADER_SIZE as u64,
        file_size: declared_len.unwrap_or(file.len() as u64),
        table_checksum: checksum64(&table),
    };
    file[..HEADER_SIZE].copy_from_slice(&header.to_bytes());
    file
}

fn entry(kind: SectionKind, offset: u64, size: u64) -> SectionEntry {
    SectionEntry {
        kind,
        version: 1,
        codec: 0,
        align_log2: 6,
        index: 0,
        flags: 0,
        offset,
        size,
        raw_size: size,
        checksum: 0,
        content_hash: ContentHash::default(),
    }
}

fn error_of(bytes: &[u8]) -> String {
    KilnFile::from_bytes(bytes, Checksums::Eager).expect_err("hostile file accepted").to_string()
}

/// A manifest body of 64 bytes (an empty manifest padded out would fail decoding; we only need
/// the layout to be judged, which happens before decoding).
const BODY: [u8; 64] = [0; 64];

#[test]
fn entry_past_the_end() {
    let e = entry(sections::MANIFEST, 128, 1 << 40);
    let msg = error_of(&craft(vec![e], &BODY, None));
    assert!(msg.contains("runs past the end"), "{msg}");
}

#[test]
fn offset_overflowing_u64() {
    let e = entry(sections::MANIFEST, u64::MAX - 63, 64);
    let msg = error_of(&craft(vec![e], &BODY, None));
    assert!(msg.contains("section offset"), "{msg}");
}

#[test]
fn overlapping_sections() {
    let a = entry(sections::MANIFEST, 192, 64);
    let b = entry(sections::VERTICES, 192, 64);
    let msg = error_of(&craft(vec![a, b], &[0u8; 128], None));
    assert!(msg.contains("overlaps"), "{msg}");
}

#[test]
fn misaligned_section() {
    let e = entry(sections::MANIFEST, 136, 56);
    let msg = error_of(&craft(vec![e], &BODY, None));
    assert!(msg.contains("misaligned"), "{msg}");
}

#[test]
fn gap_between_sections() {
    let e = entry(sections::MANIFEST, 192, 0);
    let msg = error_of(&craft(vec![e], &[0u8; 64], None));
    assert!(msg.contains("gap"), "{msg}");
}

#[test]
fn section_overlapping_the_table() {
    let e = entry(sections::MANIFEST, 64, 64);
    let msg = error_of(&craft(vec![e], &BODY, None));
    assert!(msg.contains("overlaps"), "{msg}");
}

#[test]
fn absurd_section_count() {
    let mut file = craft(vec![], &[], None);
    let mut header = Header::parse(&file).unwrap();
    header.section_count = u32::MAX;
    file[..HEADER_SIZE].copy_from_slice(&header.to_bytes());
    let msg = error_of(&file);
    assert!(msg.contains("does not fit"), "{msg}");
}

#[test]
fn unknown_codec_on_a_known_kind() {
    let mut e = entry(sections::MANIFEST, 128, 64);
    e.codec = 9;
    let msg = error_of(&craft(vec![e], &BODY, None));
    assert!(msg.contains("codec 9"), "{msg}");
}

#[test]
fn bad_alignment_field() {
    let mut e = entry(sections::MANIFEST, 128, 64);
    e.align_log2 = 3;
    let msg = error_of(&craft(vec![e], &BODY, None));
    assert!(msg.contains("alignment"), "{msg}");
}

#[test]
fn ragged_pod_section() {
    let m = entry(sections::MANIFEST, 192, 0);
    let v = entry(sections::VERTICES, 192, 40);
    let msg = error_of(&craft(vec![m, v], &[0u8; 40], None));
    assert!(msg.contains("whole number"), "{msg}");
}

#[test]
fn duplicate_sections() {
    let a = entry(sections::MANIFEST, 192, 0);
    let b = entry(sections::MANIFEST, 192, 0);
    let msg = error_of(&craft(vec![a, b], &[], None));
    assert!(msg.contains("duplicate"), "{msg}");
}

#[test]
fn missing_manifest() {
    let msg = error_of(&craft(vec![], &[], None));
    assert!(msg.contains("MANI"), "{msg}");
}

#[test]
fn zero_length_file() {
    assert!(error_of(&[]).contains("empty"));
}

#[test]
fn text_file() {
    let msg = error_of(b"# this is a README\nnot a scene\n");
    assert!(msg.contains("looks like text"), "{msg}");
}

#[test]
fn glb_file() {
    let msg = error_of(b"glTF\x02\x00\x00\x00....");
    assert!(msg.contains("glTF"), "{msg}");
}

#[test]
fn text_mode_conversions_are_diagnosed() {
    let good = common::small_file();
    let crlf_to_lf: Vec<u8> = [&good[..4], &good[5..]].concat();
    assert!(error_of(&crlf_to_lf).contains("lost a CR"));
    let lf_to_crlf: Vec<u8> = [&good[..7], b"\r", &good[7..]].concat();
    assert!(error_of(&lf_to_crlf).contains("gained a CR"));
    let mut seven_bit = good.clone();
    seven_bit[0] &= 0x7f;
    assert!(error_of(&seven_bit).contains("7-bit"));
}

#[test]
fn other_major_version_names_both_versions() {
    let mut file = common::small_file();
    file[8..10].copy_from_slice(&2u16.to_le_bytes());
    file[10..12].copy_from_slice(&3u16.to_le_bytes());
    let err = KilnFile::from_bytes(&file, Checksums::Eager).unwrap_err();
    assert!(err.is_unsupported());
    let msg = err.to_string();
    assert!(msg.contains("2.3") && msg.contains("1.x"), "{msg}");
}

#[test]
fn newer_minor_version_reads() {
    let mut file = common::small_file();
    let mut header = Header::parse(&file).unwrap();
    header.version_minor = 7;
    file[..HEADER_SIZE].copy_from_slice(&header.to_bytes());
    let f = KilnFile::from_bytes(&file, Checksums::Eager).unwrap();
    assert_eq!(f.header().version_minor, 7);
    assert_eq!(f.manifest().unwrap().scene_name, "quad");
}

#[test]
fn unknown_required_flag_is_refused_and_optional_flag_is_not() {
    let file = common::small_file();
    for (flag, refused) in [(1u32, true), (1 << 16, false)] {
        let mut f = file.clone();
        let mut header = Header::parse(&f).unwrap();
        header.flags = flag;
        f[..HEADER_SIZE].copy_from_slice(&header.to_bytes());
        assert_eq!(KilnFile::from_bytes(&f, Checksums::Eager).is_err(), refused, "flag {flag:#x}");
    }
}

#[test]
fn directory_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let err = KilnFile::open(dir.path(), Checksums::Eager).unwrap_err();
    assert!(err.to_string().contains("not a regular file"), "{err}");
}

#[test]
fn missing_file_is_an_io_error() {
    let dir = tempfile::tempdir().unwrap();
    let err = KilnFile::open(&dir.path().join("nope.kiln"), Checksums::Eager).unwrap_err();
    assert!(matches!(err.kind, kiln_format::ErrorKind::Io(_)), "{err}");
}

#[test]
fn manifest_with_absurd_length_prefix_does_not_allocate_it() {
    // A manifest claiming a 2^60-byte generator string: decoding must fail on the limit.
    let mut body = vec![0xffu8];
    body.extend_from_slice(&(1u64 << 60).to_le_bytes());
    body.resize(64, 0);
    let file = craft(vec![entry(sections::MANIFEST, 128, 64)], &body, None);
    let f = KilnFile::from_bytes(&file, Checksums::Eager).unwrap();
    let msg = f.manifest().unwrap_err().to_string();
    assert!(msg.contains("manifest"), "{msg}");
}
