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
use kiln_compiler::settings::{BRDF_LUT_RES, Codec, MEDIA_VOLUME_RES, SHADOW_RES, Settings, VoxelRes};
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
    every_kind_file_with(Codec::Auto)
}

/// The every-kind fixture with its sections compressed as `codec` says.
fn every_kind_file_with(codec: Codec) -> Vec<u8> {
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
    // Emission through the checker, so that EMLU is written.
    s.materials[0].gpu.emission = [0.5, 0.25, 0.125];
    s.materials[0].gpu.emissive_texture = 0;
    let colors = (0..s.vertices.len()).map(|i| [(i * 1031 % 65536) as u16, 7, u16::MAX, 1]).collect();
    s.set_colors(0, Some(colors));
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
    // A small environment, so that ENVH, ENVR, ENVP and ENVT are written.
    s.environment = Some(kiln_compiler::ir::EnvironmentImage {
        name: "gradient".into(),
        width: 16,
        height: 8,
        pixels: (0..128).map(|i| [0.1 + (i % 16) as f32 * 0.05, 0.2, 0.3 + (i / 16) as f32 * 0.1]).collect(),
        rotation_degrees: 0.0,
    });
    let settings = Settings {
        environment_res: kiln_compiler::settings::ENVIRONMENT_RES.min,
        voxel_res: VoxelRes::Cells(4),
        shaft_res: Some(1),
        shaft_variants: Some(Variants::ALL),
        brdf_lut_res: BRDF_LUT_RES.min,
        shadow_res: SHADOW_RES.min,
        media_volume_res: MEDIA_VOLUME_RES.min,
        // Eight probes, quickly.
        probe_spacing: Some(kiln_compiler::settings::ProbeSpacing(1.0)),
        probe_rays: Some(16),
        codec,
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
    // Both shadow-map shapes, a visibility volume for each light and the sky's three (format 1.10).
    let manifest = file.manifest().unwrap();
    let projections: Vec<_> = manifest.shadow_maps.iter().map(|m| m.projection).collect();
    assert!(projections.contains(&ShadowProjection::Cube), "{projections:?}");
    assert!(projections.contains(&ShadowProjection::Perspective), "{projections:?}");
    assert_eq!(file.all_of(sections::SHADOW_MAP).len(), manifest.shadow_maps.len());
    let sky = kiln_format::manifest::MediaVisibilityInfo::SKY;
    assert_eq!(file.all_of(sections::MEDIA_VISIBILITY).len(), manifest.lights.len() + sky.len());
    assert!(manifest.media_visibility.as_ref().is_some_and(|v| v.lights.ends_with(&sky)));
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
    for codec in [Codec::None, Codec::Auto, Codec::Zstd] {
        damage_inside_every_section_is_refused(&every_kind_file_with(codec));
    }
}

fn damage_inside_every_section_is_refused(good: &[u8]) {
    let good = good.to_vec();
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
    for codec in [Codec::Auto, Codec::Zstd] {
        kiln_verify_refuses_damage_in_every_section(&every_kind_file_with(codec));
    }
}

fn kiln_verify_refuses_damage_in_every_section(good: &[u8]) {
    let dir = tempfile::tempdir().unwrap();
    let good = good.to_vec();
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

#[test]
fn every_kind_compressed_reads_back_the_uncompressed_sections() {
    // Compiled with --codec zstd and with --codec none: the same sections, decoded bytes equal to
    // the uncompressed file's stored bytes (sliced by its own table); a section is compressed
    // exactly when the zstd library, asked directly, makes it smaller (level 9).
    let plain = every_kind_file_with(Codec::None);
    let packed = every_kind_file_with(Codec::Zstd);
    let p = KilnFile::from_bytes(&plain, Checksums::Eager).unwrap();
    let z = KilnFile::from_bytes(&packed, Checksums::Eager).unwrap();
    assert_eq!(p.sections().len(), z.sections().len());
    let mut compressed = BTreeSet::new();
    for (ps, zs) in p.sections().iter().zip(z.sections()) {
        let (pe, ze) = (ps.entry, zs.entry);
        assert_eq!((pe.kind, pe.index), (ze.kind, ze.index));
        assert_eq!(pe.codec, 0);
        let raw = &plain[pe.offset as usize..(pe.offset + pe.size) as usize];
        if pe.kind != sections::MANIFEST {
            // (The manifest records the codec setting.)
            assert_eq!(&*z.section_bytes(zs).unwrap(), raw, "{}#{}", ze.kind, ze.index);
            // The writer's frame (level 9 with content size and checksum).
            let smaller = kiln_format::codec::compress_zstd(raw, 1).unwrap().len() < raw.len();
            assert_eq!(ze.codec == 1, smaller, "{}#{}: codec {}", ze.kind, ze.index, ze.codec);
        }
        if ze.codec == 1 {
            compressed.insert(ze.kind.name());
        }
    }
    assert!(compressed.len() >= 15, "only {compressed:?} compressed");
    assert!(packed.len() < plain.len());
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("z.kiln"), &packed).unwrap();
    let run = kiln(dir.path(), &["verify", "z.kiln", "--rays", "64"]);
    run.expect(0);
    assert!(run.stdout.contains(&format!("{} compressed)", compressed_count(&z))), "{run:?}");
}

#[test]
fn kiln_verify_refuses_a_frame_that_does_not_decode_in_every_compressed_section() {
    // Each compressed section's frame overwritten under good checksums (so only the frame rules
    // can catch it): verify exits 1 naming the section and the decoding error.
    let dir = tempfile::tempdir().unwrap();
    let good = every_kind_file_with(Codec::Zstd);
    let file = KilnFile::from_bytes(&good, Checksums::Eager).unwrap();
    let compressed: Vec<_> = file.sections().iter().filter(|s| s.entry.codec == 1).copied().collect();
    assert!(!compressed.is_empty());
    for s in compressed {
        // Flip a bit pattern in the frame's last byte (part of zstd's content checksum).
        let mut bad = good.clone();
        let last = (s.entry.offset + s.entry.size - 1) as usize;
        bad[last] ^= 0x5a;
        let bad = rechecksummed_as_is(&bad, s.position);
        std::fs::write(dir.path().join("bad.kiln"), &bad).unwrap();
        let run = kiln(dir.path(), &["verify", "bad.kiln"]);
        run.expect(1)
            .says(&format!("({}#{})", s.entry.kind, s.entry.index))
            .says("compressed section cannot be decoded");
    }
}

fn compressed_count(file: &KilnFile) -> usize {
    file.sections().iter().filter(|s| s.entry.codec == 1).count()
}

/// `bytes` with the checksums of section `position`, the table and the header made right for
/// the bytes as they are.
fn rechecksummed_as_is(bytes: &[u8], position: usize) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let mut header = Header::parse(&out).unwrap();
    let table = header.table_offset as usize;
    let at = table + position * ENTRY_SIZE;
    let mut entry = SectionEntry::from_bytes(&out[at..at + ENTRY_SIZE]);
    let (o, n) = (entry.offset as usize, entry.size as usize);
    entry.checksum = checksum64(&out[o..o + n]);
    out[at..at + ENTRY_SIZE].copy_from_slice(&entry.to_bytes());
    let end = table + header.section_count as usize * ENTRY_SIZE;
    header.table_checksum = checksum64(&out[table..end]);
    out[..HEADER_SIZE].copy_from_slice(&header.to_bytes());
    out
}

/// `good` (stored as is) with section `kind` edited by `edit` and every checksum made right.
fn edited(good: &[u8], kind: SectionKind, edit: impl FnOnce(&mut [u8])) -> Vec<u8> {
    let file = KilnFile::from_bytes(good, Checksums::Eager).unwrap();
    let s = *file.find(kind, 0).expect("the fixture holds the section");
    assert_eq!(s.entry.codec, 0, "stored as is");
    let mut out = good.to_vec();
    edit(&mut out[s.entry.offset as usize..(s.entry.offset + s.entry.size) as usize]);
    rechecksummed_as_is(&out, s.position)
}

#[test]
fn kiln_verify_without_rays_refuses_boxes_and_a_grid_that_do_not_bound_the_scene() {
    let good = every_kind_file_with(Codec::None);
    let dir = tempfile::tempdir().unwrap();
    let verify = |bytes: &[u8]| {
        std::fs::write(dir.path().join("bad.kiln"), bytes).unwrap();
        kiln(dir.path(), &["verify", "bad.kiln"])
    };
    verify(&good).expect(0);
    // A node's slot box shrunk to the point at its grid's far corner (every plane 255): a leaf
    // slot's triangles, or an internal slot's child boxes, no longer lie in it. The byte
    // offsets are FORMAT.md's CWBV node layout (80 bytes; child_meta at 24, the planes from 32).
    let nodes = {
        let file = KilnFile::from_bytes(&good, Checksums::Eager).unwrap();
        file.pod::<sections::CwbvhNode>(sections::BVH_NODES, 0).unwrap().unwrap().to_vec()
    };
    let slot_of = |internal: bool| {
        nodes.iter().enumerate().find_map(|(i, n)| {
            (0..8).find(|&s| n.child_meta[s] != 0 && ((n.imask >> s) & 1 == 1) == internal).map(|s| (i, s))
        })
    };
    for (what, internal, says) in
        [("leaf", false, "lies outside its leaf's box"), ("internal", true, "is not within its parent's box")]
    {
        let (node, slot) = slot_of(internal).unwrap_or_else(|| panic!("a {what} slot"));
        let bad = edited(&good, sections::BVH_NODES, |b| {
            for plane in 0..6 {
                b[node * 80 + 32 + plane * 8 + slot] = 255;
            }
        });
        verify(&bad).expect(1).says("BVH node").says(says);
    }
    // The grid moved by eight cells along x: it no longer covers the scene (origin at byte 0,
    // the cell edge at 24, both f64).
    let bad = edited(&good, sections::GRID, |b| {
        let origin = f64::from_le_bytes(b[0..8].try_into().unwrap());
        let cell = f64::from_le_bytes(b[24..32].try_into().unwrap());
        b[0..8].copy_from_slice(&(origin + 8.0 * cell).to_le_bytes());
    });
    verify(&bad).expect(1).says("do not cover the scene");
}
