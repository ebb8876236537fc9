//! Codec 1 (zstd): compressed sections round-trip; damage to a compressed file is refused, and
//! so is damage behind a good checksum (a frame cut short, followed by bytes, declaring another
//! size); a declared decoded size beyond the reader's limit is refused before anything of that
//! size is allocated (a tracking allocator in this test binary watches every allocation).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use kiln_format::checksum::checksum64;
use kiln_format::header::{HEADER_SIZE, Header, VERSION_MAJOR};
use kiln_format::table::{Codec, ENTRY_SIZE, SectionEntry, SectionKind};
use kiln_format::{Checksums, Compression, ContentHash, ErrorKind, KilnFile, Manifest, SceneView, sections};
use proptest::prelude::*;

// ------------------------------------------------------------------ allocation tracking

/// The system allocator, recording the largest single request made on the current thread.
struct Tracking;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: every call is forwarded unchanged to `System`; the bookkeeping touches only a
// const-initialised thread-local `Cell`, which neither allocates nor re-enters the allocator.
unsafe impl GlobalAlloc for Tracking {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(layout.size())));
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(layout.size())));
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(new_size)));
        // SAFETY: forwarded unchanged.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Tracking = Tracking;

/// Runs `f` and returns its result with the largest allocation it asked for on this thread.
fn largest_allocation<T>(f: impl FnOnce() -> T) -> (T, usize) {
    LARGEST.with(|l| l.set(0));
    let out = f();
    (out, LARGEST.with(|l| l.get()))
}

// ------------------------------------------------------------------ fixtures

/// A file laid out by FORMAT.md's placement rule from `(kind, codec, raw_size, stored bytes)`,
/// with every checksum right, so that only what the codec rules judge can be wrong.
fn craft(sections: &[(SectionKind, u8, u64, Vec<u8>)]) -> Vec<u8> {
    let table_end = HEADER_SIZE + ENTRY_SIZE * sections.len();
    let mut file = vec![0u8; table_end];
    let mut entries = Vec::new();
    for (i, (kind, codec, raw_size, stored)) in sections.iter().enumerate() {
        file.resize(file.len().div_ceil(64) * 64, 0);
        entries.push(SectionEntry {
            kind: *kind,
            version: if *kind == sections::MANIFEST { kiln_format::manifest::MANIFEST_VERSION } else { 1 },
            codec: *codec,
            align_log2: 6,
            index: 0,
            flags: 0,
            offset: file.len() as u64,
            size: stored.len() as u64,
            raw_size: *raw_size,
            checksum: checksum64(stored),
            content_hash: ContentHash::of(&[i as u8]),
        });
        file.extend_from_slice(stored);
    }
    let table: Vec<u8> = entries.iter().flat_map(|e| e.to_bytes()).collect();
    file[HEADER_SIZE..table_end].copy_from_slice(&table);
    let header = Header {
        version_major: VERSION_MAJOR,
        version_minor: 2,
        flags: 0,
        section_count: entries.len() as u32,
        table_offset: HEADER_SIZE as u64,
        file_size: file.len() as u64,
        table_checksum: checksum64(&table),
    };
    file[..HEADER_SIZE].copy_from_slice(&header.to_bytes());
    file
}

/// 4000 bytes of triangle materials (u32 each) with some structure for zstd to find.
fn tmat_bytes() -> Vec<u8> {
    (0..1000u32).flat_map(|i| (i / 7 % 3).to_le_bytes()).collect()
}

/// A zstd frame as FORMAT.md asks for, made with the zstd library directly (content size
/// declared, content checksum on).
fn frame(bytes: &[u8]) -> Vec<u8> {
    let mut c = zstd::bulk::Compressor::new(3).unwrap();
    c.set_parameter(zstd::zstd_safe::CParameter::ChecksumFlag(true)).unwrap();
    c.compress(bytes).unwrap()
}

/// A manifest and a zstd-coded `TMAT` section of `raw_size` with `stored` bytes.
fn with_tmat(raw_size: u64, stored: Vec<u8>) -> Vec<u8> {
    let manifest = Manifest { scene_name: "codec".into(), ..Default::default() }.encode();
    let len = manifest.len() as u64;
    craft(&[
        (sections::MANIFEST, Codec::None as u8, len, manifest),
        (sections::TRIANGLE_MATERIALS, Codec::Zstd as u8, raw_size, stored),
    ])
}

/// The decoded `TMAT` section of `bytes`, or the first error opening or decoding it.
fn tmat(bytes: &[u8], policy: Checksums) -> Result<Vec<u8>, kiln_format::FormatError> {
    let file = KilnFile::from_bytes(bytes, policy)?;
    let s = *file.find(sections::TRIANGLE_MATERIALS, 0).expect("the section is there");
    file.section_bytes(&s).map(|b| b.into_owned())
}

fn is_decode_error(r: &Result<Vec<u8>, kiln_format::FormatError>) -> bool {
    matches!(r, Err(e) if matches!(e.kind, ErrorKind::Decode(_)))
}

/// Accepted as a whole: opens with every checksum verified and the scene view validates.
fn accepts(bytes: &[u8]) -> bool {
    match KilnFile::from_bytes(bytes, Checksums::Eager) {
        Ok(f) => SceneView::new(&f).is_ok(),
        Err(_) => false,
    }
}

// ------------------------------------------------------------------ tests

#[test]
fn compressed_sections_decode_to_the_uncompressed_files_bytes() {
    let plain = common::small_file_with(32, Compression::None);
    let packed = common::small_file_with(32, Compression::All);
    assert!(packed.len() < plain.len(), "{} vs {}", packed.len(), plain.len());
    let p = KilnFile::from_bytes(&plain, Checksums::Eager).unwrap();
    let z = KilnFile::from_bytes(&packed, Checksums::Eager).unwrap();
    assert_eq!(z.header().version_minor, kiln_format::header::VERSION_MINOR);
    let texture = z.find(sections::TEXTURE, 0).unwrap().entry;
    assert_eq!(texture.codec, Codec::Zstd as u8, "the 32x32 texture is compressed");
    assert!(texture.size < texture.raw_size);
    assert_eq!(p.sections().len(), z.sections().len());
    for (ps, zs) in p.sections().iter().zip(z.sections()) {
        let (pe, ze) = (ps.entry, zs.entry);
        assert_eq!((pe.kind, pe.index, pe.content_hash), (ze.kind, ze.index, ze.content_hash));
        // The uncompressed file's stored bytes, sliced by its table: the expected content.
        let expected = &plain[pe.offset as usize..(pe.offset + pe.size) as usize];
        assert_eq!(ze.raw_size, pe.size);
        assert_eq!(&*z.section_bytes(zs).unwrap(), expected, "{}", ze.kind);
        // A frame is kept only when smaller; otherwise the section is stored as is.
        assert!(ze.codec == Codec::None as u8 || ze.size < ze.raw_size);
    }
    // The scene view (POD views of decoded sections) sees the same scene.
    let (pv, zv) = (SceneView::new(&p).unwrap(), SceneView::new(&z).unwrap());
    assert_eq!(pv.texture(0).unwrap(), zv.texture(0).unwrap());
    assert_eq!(bytemuck::cast_slice::<_, u8>(pv.vertices), bytemuck::cast_slice::<_, u8>(zv.vertices));
    assert_eq!(pv.triangles, zv.triangles);
    // Writing is deterministic.
    assert_eq!(packed, common::small_file_with(32, Compression::All));
}

#[test]
fn every_byte_damage_of_a_compressed_file_is_refused() {
    let good = common::small_file_with(32, Compression::All);
    assert!(accepts(&good));
    let file = KilnFile::from_bytes(&good, Checksums::Eager).unwrap();
    assert!(file.sections().iter().any(|s| s.entry.codec == Codec::Zstd as u8));
    let mut bytes = good.clone();
    for i in 0..good.len() {
        for mask in [0x01u8, 0x80, 0xff] {
            bytes[i] ^= mask;
            let (accepted, largest) = largest_allocation(|| accepts(&bytes));
            assert!(!accepted, "flip {mask:#04x} of byte {i} of {} was accepted", good.len());
            assert!(largest < 1 << 20, "flip {mask:#04x} of byte {i}: an allocation of {largest} bytes");
            // With checksums deferred nothing catches the damage up front: reading every
            // section must still end in an error or the original bytes, never a panic.
            if let Ok(f) = KilnFile::from_bytes(&bytes, Checksums::Deferred) {
                for s in f.sections() {
                    let _ = f.section_bytes(s);
                }
                let _ = SceneView::new(&f);
            }
            bytes[i] = good[i];
        }
    }
    for len in 0..good.len() {
        assert!(!accepts(&good[..len]), "truncation to {len} bytes was accepted");
    }
}

#[test]
fn damage_inside_a_frame_behind_a_good_checksum_is_refused_or_harmless() {
    // Every bit pattern flip of every byte of a frame, with the section, table and header
    // checksums made right again: the frame rules and zstd's content checksum must refuse it,
    // or it must still decode to the same bytes (never to other bytes, never a panic).
    let raw = tmat_bytes();
    let f = frame(&raw);
    for i in 0..f.len() {
        for mask in [0x01u8, 0x10, 0x80, 0xff] {
            let mut bad = f.clone();
            bad[i] ^= mask;
            let (got, largest) =
                largest_allocation(|| tmat(&with_tmat(raw.len() as u64, bad), Checksums::Eager));
            assert!(largest < 1 << 20, "byte {i} ^ {mask:#x}: an allocation of {largest} bytes");
            match got {
                Ok(bytes) => {
                    assert_eq!(bytes, raw, "byte {i} ^ {mask:#x} of the frame decoded to other bytes")
                }
                Err(e) => assert!(matches!(e.kind, ErrorKind::Decode(_)), "byte {i} ^ {mask:#x}: {e}"),
            }
        }
    }
}

#[test]
fn a_truncated_frame_trailing_bytes_or_another_declared_size_are_refused() {
    let raw = tmat_bytes();
    let f = frame(&raw);
    let n = raw.len() as u64;
    assert_eq!(tmat(&with_tmat(n, f.clone()), Checksums::Eager).unwrap(), raw);
    // Every truncation of the frame (the table's size and checksum agreeing with it).
    for len in 0..f.len() {
        let r = tmat(&with_tmat(n, f[..len].to_vec()), Checksums::Eager);
        assert!(is_decode_error(&r), "frame cut to {len} of {} bytes: {r:?}", f.len());
    }
    // A byte after the frame, a second frame after it.
    let r = tmat(&with_tmat(n, [&f[..], &[0]].concat()), Checksums::Eager);
    assert!(is_decode_error(&r) && format!("{r:?}").contains("follow"), "{r:?}");
    let r = tmat(&with_tmat(2 * n, [&f[..], &f[..]].concat()), Checksums::Eager);
    assert!(is_decode_error(&r), "two frames: {r:?}");
    // A table raw_size other than the frame's content size, either way.
    for other in [n - 4, n + 4] {
        let r = tmat(&with_tmat(other, f.clone()), Checksums::Eager);
        assert!(is_decode_error(&r), "raw_size {other} for {n}: {r:?}");
    }
    // A frame that does not declare its size, and a skippable frame.
    let mut c = zstd::bulk::Compressor::new(3).unwrap();
    c.set_parameter(zstd::zstd_safe::CParameter::ContentSizeFlag(false)).unwrap();
    let streamed = c.compress(&raw).unwrap();
    assert!(
        matches!(zstd::zstd_safe::get_frame_content_size(&streamed), Ok(None)),
        "the fixture declares no size"
    );
    let r = tmat(&with_tmat(n, streamed), Checksums::Eager);
    assert!(is_decode_error(&r) && format!("{r:?}").contains("declare"), "{r:?}");
    let mut skippable = vec![0x50, 0x2A, 0x4D, 0x18];
    skippable.extend_from_slice(&4u32.to_le_bytes());
    skippable.extend_from_slice(&[0; 4]);
    let r = tmat(&with_tmat(n, skippable), Checksums::Eager);
    assert!(is_decode_error(&r), "skippable frame: {r:?}");
}

#[test]
fn a_declared_size_beyond_the_limit_is_refused_before_allocating_it() {
    let raw = tmat_bytes();
    let f = frame(&raw);
    // 2^50 bytes declared (a whole number of u32s): refused while opening, with no allocation
    // anywhere near that size, under the default limit (4 GiB).
    let huge = 1u64 << 50;
    for policy in [Checksums::Eager, Checksums::OnAccess, Checksums::Deferred] {
        let bytes = with_tmat(huge, f.clone());
        // Opening and reading the section: wherever the reader checks the limit (while
        // validating the layout, and again before decoding), it must be before allocating.
        let (r, largest) = largest_allocation(|| {
            KilnFile::from_bytes(&bytes, policy).and_then(|f| {
                let s = *f.find(sections::TRIANGLE_MATERIALS, 0).expect("the section is there");
                f.section_bytes(&s).map(|_| ())
            })
        });
        let e = r.unwrap_err();
        assert_eq!(e.kind, ErrorKind::DecodedTooLarge { declared: huge, limit: 1 << 32 }, "{e}");
        assert!(largest < 1 << 20, "{policy:?}: an allocation of {largest} bytes");
    }
    // A limit far below a real section's size: refused; at its size: read.
    let bytes = with_tmat(raw.len() as u64, f.clone());
    let (r, largest) =
        largest_allocation(|| KilnFile::from_bytes_limited(&bytes, Checksums::Eager, 1000).map(|_| ()));
    assert_eq!(r.unwrap_err().kind, ErrorKind::DecodedTooLarge { declared: raw.len() as u64, limit: 1000 });
    assert!(largest < 1 << 20);
    let file = KilnFile::from_bytes_limited(&bytes, Checksums::Eager, raw.len() as u64).unwrap();
    let s = *file.find(sections::TRIANGLE_MATERIALS, 0).unwrap();
    assert_eq!(&*file.section_bytes(&s).unwrap(), &raw[..]);
    assert_eq!(file.decode_section(s.position).unwrap(), raw.len() as u64);
}

#[test]
fn compressed_kinds_this_reader_skips_are_not_limited() {
    // An unknown kind is skipped, so its declared size is never acted on.
    let manifest = Manifest::default().encode();
    let len = manifest.len() as u64;
    let bytes = craft(&[
        (sections::MANIFEST, 0, len, manifest),
        (SectionKind(*b"ZZZZ"), 1, 1 << 50, frame(b"unknown")),
    ]);
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    assert_eq!(file.skipped().count(), 1);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Any section content round-trips through the writer's compression, whether or not the
    /// frame is kept.
    #[test]
    fn any_section_round_trips(words in proptest::collection::vec(0u32..8, 0..3000), noise in any::<bool>()) {
        let data: Vec<u32> = words.iter().enumerate()
            .map(|(i, &w)| if noise { w.wrapping_mul(0x9E37_79B9).rotate_left(i as u32 % 31) } else { w })
            .collect();
        let manifest = Manifest::default();
        let mut w = kiln_format::FileWriter::new();
        w.compression(Compression::All);
        w.manifest(&manifest, ContentHash::of(b"m")).unwrap();
        w.pod(sections::TRIANGLE_MATERIALS, 0, &data, ContentHash::of(b"t")).unwrap();
        let bytes = w.to_bytes().unwrap();
        let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
        prop_assert_eq!(file.pod::<u32>(sections::TRIANGLE_MATERIALS, 0).unwrap().unwrap_or(&[]), &data[..]);
        prop_assert_eq!(file.manifest().unwrap(), manifest);
    }

    /// Arbitrary stored bytes under a good checksum, declared zstd: an error or exactly
    /// raw_size bytes, never a panic or a large allocation.
    #[test]
    fn arbitrary_frames_never_panic(stored in proptest::collection::vec(any::<u8>(), 0..200),
                                    prefix in any::<bool>(), raw_words in 0u64..5000) {
        let mut stored = stored;
        if prefix {
            // Mostly a real frame header, so that the decoder gets past the magic.
            let mut f = frame(&tmat_bytes());
            f.truncate(12.min(f.len()));
            f.extend_from_slice(&stored);
            stored = f;
        }
        let raw_size = raw_words * 4;
        let bytes = with_tmat(raw_size, stored);
        let (r, largest) = largest_allocation(|| tmat(&bytes, Checksums::Eager));
        prop_assert!(largest < 1 << 20);
        if let Ok(b) = r {
            prop_assert_eq!(b.len() as u64, raw_size);
        }
    }
}

/// `n` bytes of which the fraction `random` are pseudo-random (xorshift, incompressible) and
/// the rest zeros, interleaved in 64-byte runs so that zstd sees both throughout.
fn partly_random(n: usize, random: f64, seed: u64) -> Vec<u8> {
    let mut x = seed | 1;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    (0..n)
        .map(|i| {
            let run = i / 64;
            let v = next();
            if (run as f64 * random).fract() + random >= 1.0 || random >= 1.0 { v as u8 } else { 0 }
        })
        .collect()
}

#[test]
fn the_default_policy_keeps_a_frame_only_when_it_saves_an_eighth() {
    // Three shadow-map-sized sections: zeros (saves ~all), 30 % zeros (saves ~30 %), 5 % zeros
    // (saves ~5 %). Whether each frame saves an eighth is judged from zstd's own level-9 frame
    // (a few header bytes apart from the writer's; the margins are kilobytes).
    let n = 64 << 10;
    let parts = [partly_random(n, 0.0, 1), partly_random(n, 0.7, 2), partly_random(n, 0.95, 3)];
    let saves_an_eighth: Vec<bool> =
        parts.iter().map(|p| zstd::bulk::compress(p, 9).unwrap().len() * 8 <= p.len() * 7).collect();
    assert_eq!(saves_an_eighth, [true, true, false], "the test's data is not what it means to be");
    let write = |compression| {
        let mut w = kiln_format::FileWriter::new();
        w.compression(compression);
        w.manifest(&Manifest { generator: "test".into(), ..Default::default() }, ContentHash::of(b"m"))
            .unwrap();
        for (i, p) in parts.iter().enumerate() {
            w.bytes(sections::SHADOW_MAP, i as u32, p.as_slice(), ContentHash::of(&[i as u8])).unwrap();
        }
        w.to_bytes().unwrap()
    };
    let codecs = |bytes: &[u8]| -> Vec<bool> {
        let f = KilnFile::from_bytes(bytes, Checksums::Eager).unwrap();
        (0..3).map(|i| f.find(sections::SHADOW_MAP, i).unwrap().entry.codec == Codec::Zstd as u8).collect()
    };
    assert_eq!(codecs(&write(Compression::Default)), saves_an_eighth);
    // `All` keeps every frame that is smaller at all; `None` none.
    assert_eq!(codecs(&write(Compression::All)), [true, true, true]);
    assert_eq!(codecs(&write(Compression::None)), [false, false, false]);
    // Either way the decoded bytes are the section's.
    let f = write(Compression::Default);
    let f = KilnFile::from_bytes(&f, Checksums::Eager).unwrap();
    for (i, p) in parts.iter().enumerate() {
        let s = f.find(sections::SHADOW_MAP, i as u32).unwrap();
        assert_eq!(&*f.section_bytes(s).unwrap(), p.as_slice());
    }
}

#[test]
fn decoding_sections_in_parallel_gives_each_section_and_reports_damage() {
    // Every section of a compressed file decoded at once on all cores equals its bytes read one
    // by one from an uncompressed copy; a damaged section is reported, not skipped.
    let z = common::small_file_with(32, Compression::All);
    let p = common::small_file_with(32, Compression::None);
    let (zf, pf) = (
        KilnFile::from_bytes(&z, Checksums::OnAccess).unwrap(),
        KilnFile::from_bytes(&p, Checksums::Eager).unwrap(),
    );
    let all: Vec<usize> = (0..zf.sections().len()).collect();
    zf.decode_sections(&all).unwrap();
    for (zs, ps) in zf.sections().iter().zip(pf.sections()) {
        assert_eq!(
            &*zf.section_bytes(zs).unwrap(),
            &p[ps.entry.offset as usize..(ps.entry.offset + ps.entry.size) as usize]
        );
    }
    let tex = zf.find(sections::TEXTURE, 0).unwrap();
    assert_eq!(tex.entry.codec, Codec::Zstd as u8);
    let mut bad = z.clone();
    bad[(tex.entry.offset + tex.entry.size / 2) as usize] ^= 0x40;
    let bf = KilnFile::from_bytes(&bad, Checksums::OnAccess).unwrap();
    let err = bf.decode_sections(&all).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::Checksum { .. }), "{err}");
}

/// The writer's frames are a function of the section's bytes alone: zstd's multithreaded
/// compressor gives the same frame for one worker and for several (and asking for none still
/// gets that compressor, not the single-threaded one, whose frames differ), and the frame
/// decodes, by the zstd library directly, to the bytes. 40 MiB of records with some structure:
/// more than two of the compressor's jobs at the writer's level.
#[test]
fn frames_do_not_depend_on_the_worker_count() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let bytes: Vec<u8> = (0..10 << 20)
        .flat_map(|i: u32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let word = if state.is_multiple_of(4) { state as u32 & 0x3ff_03ff } else { i / 64 };
            word.to_le_bytes()
        })
        .collect();
    let one = kiln_format::codec::compress_zstd(&bytes, 1).unwrap();
    assert!(one.len() < bytes.len() / 2, "the records compress ({} of {} bytes)", one.len(), bytes.len());
    for workers in [0, 2, 5] {
        let frame = kiln_format::codec::compress_zstd(&bytes, workers).unwrap();
        assert!(
            frame == one,
            "{workers} workers made another frame ({} bytes, one worker {})",
            frame.len(),
            one.len()
        );
    }
    let mut single = zstd::bulk::Compressor::new(kiln_format::codec::ZSTD_LEVEL).unwrap();
    single.set_parameter(zstd::zstd_safe::CParameter::ChecksumFlag(true)).unwrap();
    assert!(single.compress(&bytes).unwrap() != one, "the single-threaded compressor's frame is another");
    assert!(zstd::bulk::decompress(&one, bytes.len()).unwrap() == bytes, "the frame decodes to the bytes");
}

/// A zstd frame of `n` zero bytes, written in 1 MiB pieces (never holding `n` bytes).
fn frame_of_zeros(n: u64) -> Vec<u8> {
    use std::io::Write;
    let mut e = zstd::stream::Encoder::new(Vec::new(), 1).unwrap();
    e.set_pledged_src_size(Some(n)).unwrap();
    e.include_checksum(true).unwrap();
    let piece = vec![0u8; 1 << 20];
    for _ in 0..n / (1 << 20) {
        e.write_all(&piece).unwrap();
    }
    e.finish().unwrap()
}

#[test]
fn a_section_whose_declared_size_contradicts_its_record_is_refused_before_decoding() {
    // A spot light's 16 x 16 shadow map (1 KiB of depths) stored as a frame of 256 MiB of zeros:
    // a consistent frame and table within the per-section limit, but not what the manifest's
    // record says. The view must refuse it without allocating the 256 MiB.
    let declared = 256u64 << 20;
    let light = kiln_format::manifest::Light {
        name: "spot".into(),
        kind: kiln_format::manifest::LightKind::Spot { inner_cone: 0.3, outer_cone: 0.5 },
        position: [0.0; 3],
        direction: [0.0, -1.0, 0.0],
        right: [0.0; 3],
        color: [1.0; 3],
        intensity: 1.0,
        range: 0.0,
        casts_shadows: true,
    };
    let info = kiln_format::manifest::ShadowMapInfo {
        light: 0,
        projection: kiln_format::manifest::ShadowProjection::Perspective,
        resolution: 16,
        view_proj: [0.0; 16],
        origin: [0.0; 3],
        direction: [0.0, -1.0, 0.0],
        near: 0.1,
        far: 10.0,
        texel: 0.01,
    };
    let manifest = Manifest {
        scene_name: "shadow".into(),
        lights: vec![light],
        shadow_maps: vec![info],
        ..Default::default()
    }
    .encode();
    let len = manifest.len() as u64;
    let zeros = frame_of_zeros(declared);
    assert!(zeros.len() < 64 << 10, "{} bytes of frame", zeros.len());
    let bytes = craft(&[
        (sections::MANIFEST, Codec::None as u8, len, manifest.clone()),
        (sections::SHADOW_MAP, Codec::Zstd as u8, declared, zeros),
    ]);
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).expect("the layout is consistent");
    let (r, largest) = largest_allocation(|| SceneView::new(&file).map(|_| ()));
    let e = r.expect_err("a 256 MiB shadow map for a 16 x 16 record").to_string();
    assert!(
        e.contains("shadow map 0") && e.contains(&declared.to_string()) && e.contains("256 elements"),
        "{e}"
    );
    assert!(largest < 1 << 20, "an allocation of {largest} bytes");
    // The check bulk decoders (kiln verify, the player) run before decoding anything.
    let (r, largest) = largest_allocation(|| kiln_format::scene::check_declared_sizes(&file));
    let e = r.expect_err("refused before decoding").to_string();
    assert!(e.contains("shadow map 0") && e.contains(&declared.to_string()), "{e}");
    assert!(largest < 1 << 20, "an allocation of {largest} bytes");
    // The same record with the 1 KiB it declares is read (the check is not a refusal of all).
    let depths: Vec<u8> = (0..256).flat_map(|_| 1.0f32.to_le_bytes()).collect();
    let bytes = craft(&[
        (sections::MANIFEST, Codec::None as u8, len, manifest),
        (sections::SHADOW_MAP, Codec::Zstd as u8, 1024, frame(&depths)),
    ]);
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let r = SceneView::new(&file).map(|_| ());
    assert!(r.as_ref().is_err_and(|e| !e.to_string().contains("table declares")) || r.is_ok(), "{r:?}");
}
