//! Fuzzes what lies behind the checksums: the input's header and table checksums, section
//! checksums and length field are recomputed before reading, so that mutations reach the
//! layout rules, zstd frame decoding, manifest decoding and scene validation instead of stopping
//! at a checksum.
#![no_main]

use kiln_format::checksum::checksum64;
use kiln_format::header::{HEADER_SIZE, MAGIC};
use kiln_format::table::{ENTRY_SIZE, SectionEntry};
use kiln_format::{Checksums, KilnFile, SceneView};
use libfuzzer_sys::fuzz_target;

fn fix(data: &[u8]) -> Vec<u8> {
    let mut f = data.to_vec();
    if f.len() < HEADER_SIZE {
        return f;
    }
    f[..8].copy_from_slice(&MAGIC);
    let len = f.len() as u64;
    f[32..40].copy_from_slice(&len.to_le_bytes());
    let count = u32::from_le_bytes([f[20], f[21], f[22], f[23]]) as usize;
    let table_end = HEADER_SIZE + count.min((f.len() - HEADER_SIZE) / ENTRY_SIZE) * ENTRY_SIZE;
    for at in (HEADER_SIZE..table_end).step_by(ENTRY_SIZE) {
        let mut e = SectionEntry::from_bytes(&f[at..at + ENTRY_SIZE]);
        let end = e.offset.checked_add(e.size);
        if let Some(end) = end.filter(|&end| end <= len) {
            e.checksum = checksum64(&f[e.offset as usize..end as usize]);
            f[at..at + ENTRY_SIZE].copy_from_slice(&e.to_bytes());
        }
    }
    let table = checksum64(&f[HEADER_SIZE..table_end]);
    f[40..48].copy_from_slice(&table.to_le_bytes());
    let header = checksum64(&f[..56]);
    f[56..64].copy_from_slice(&header.to_le_bytes());
    f
}

fuzz_target!(|data: &[u8]| {
    let bytes = fix(data);
    let Ok(file) = KilnFile::from_bytes(&bytes, Checksums::Eager) else { return };
    let _ = file.manifest();
    // Compressed sections (codec 1) reach the zstd frame checks and the bounded decoder here,
    // since their checksums were made right above.
    for s in file.sections() {
        if let Ok(bytes) = file.section_bytes(s) {
            assert_eq!(bytes.len() as u64, s.entry.raw_size, "a section decoded to another size");
        }
    }
    if let Ok(view) = SceneView::new(&file) {
        let t = kiln_format::query::IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
        let q = kiln_format::query::BvhQuery::new(view.bvh, &t);
        for d in [glam::Vec3::X, glam::Vec3::NEG_Y, glam::Vec3::ONE.normalize()] {
            let ray = kiln_format::query::Ray::new(glam::Vec3::splat(0.25), d, 0.0, f32::INFINITY);
            let _ = q.closest_hit(&ray);
            let _ = q.any_hit(&ray);
        }
    }
});
