//! Damage: every single-byte change and every truncation of a real file is refused.

mod common;

use kiln_format::{Checksums, KilnFile, SceneView};

fn accepts(bytes: &[u8]) -> bool {
    match KilnFile::from_bytes(bytes, Checksums::Eager) {
        Ok(f) => SceneView::new(&f).is_ok(),
        Err(_) => false,
    }
}

#[test]
fn the_fixture_is_sound() {
    assert!(accepts(&common::small_file()));
}

#[test]
fn every_single_byte_flip_is_refused() {
    let good = common::small_file();
    let mut bytes = good.clone();
    for i in 0..good.len() {
        for mask in [0x01u8, 0x80, 0xff] {
            bytes[i] ^= mask;
            assert!(!accepts(&bytes), "flip {mask:#04x} of byte {i} of {} was accepted", good.len());
            bytes[i] = good[i];
        }
    }
}

#[test]
fn every_truncation_is_refused() {
    let good = common::small_file();
    for len in 0..good.len() {
        assert!(!accepts(&good[..len]), "truncation to {len} bytes was accepted");
    }
}

#[test]
fn appended_bytes_are_refused() {
    let mut bytes = common::small_file();
    bytes.push(0);
    let err = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap_err();
    assert!(err.to_string().contains("trailing"), "{err}");
}

#[test]
fn on_access_policy_reports_damage_on_access() {
    let good = common::small_file();
    let file = KilnFile::from_bytes(&good, Checksums::OnAccess).unwrap();
    let last = file.sections().last().unwrap().entry;
    let mut bad = good.clone();
    bad[last.offset as usize] ^= 1;
    let file = KilnFile::from_bytes(&bad, Checksums::OnAccess).expect("layout is intact");
    let s = *file.sections().last().unwrap();
    let err = file.section_bytes(&s).unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("checksum mismatch") && msg.contains(&format!("{:#x}", last.offset)), "{msg}");
}
