//! Reading: validate everything about the layout before handing out any byte.

use std::borrow::Cow;
use std::fs::File;
use std::path::Path;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use bytemuck::Pod;
use memmap2::Mmap;

use crate::checksum::checksum64;
use crate::codec::{Aligned, DEFAULT_MAX_DECODED, decode_zstd};
use crate::error::{ErrorKind, FormatError, Result};
use crate::header::{HEADER_SIZE, Header};
use crate::manifest::Manifest;
use crate::sections::{self, KindInfo, MANIFEST};
use crate::table::{Codec, ENTRY_SIZE, MAX_ALIGN_LOG2, MIN_ALIGN_LOG2, SectionEntry, SectionKind, align_up};

/// When section checksums are verified.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Checksums {
    /// All of them while opening; opening fails on the first mismatch.
    Eager,
    /// Each section the first time its bytes are asked for (the default).
    #[default]
    OnAccess,
    /// Never by the accessors; call [`KilnFile::verify_section`] yourself (e.g. while
    /// uploading). The header and table checksums are always verified.
    Deferred,
}

enum Backing {
    Mapped(Mmap),
    Owned(Aligned),
}

impl Backing {
    fn bytes(&self) -> &[u8] {
        match self {
            Backing::Mapped(m) => m,
            Backing::Owned(a) => a.bytes(),
        }
    }

    fn copy_of(bytes: &[u8]) -> Backing {
        Backing::Owned(Aligned::copy_of(bytes))
    }
}

/// A section found in the table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Section {
    /// Position in the table (0-based).
    pub position: usize,
    /// The table entry.
    pub entry: SectionEntry,
    /// What this reader knows of the kind; `None` for kinds it skips (unknown, or a newer
    /// version of a known kind).
    pub known: Option<&'static KindInfo>,
}

/// An opened, layout-validated `.kiln` file.
pub struct KilnFile {
    backing: Backing,
    header: Header,
    sections: Vec<Section>,
    verified: Vec<OnceLock<Result<()>>>,
    /// Compressed sections, decoded once on first access and kept for the file's lifetime (so
    /// that [`KilnFile::pod`] can lend them like mapped ones).
    decoded: Vec<OnceLock<Result<Aligned>>>,
    policy: Checksums,
    max_decoded: u64,
    decode_nanos: AtomicU64,
}

impl std::fmt::Debug for KilnFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KilnFile")
            .field("header", &self.header)
            .field("sections", &self.sections.len())
            .finish()
    }
}

impl KilnFile {
    /// Opens and memory-maps `path`, then validates its layout.
    pub fn open(path: &Path, policy: Checksums) -> Result<KilnFile> {
        Self::open_limited(path, policy, DEFAULT_MAX_DECODED)
    }

    /// [`KilnFile::open`] with a limit on the decoded size of each compressed section: a file
    /// declaring a larger `raw_size` for a compressed section of a known kind is refused before
    /// anything is allocated.
    pub fn open_limited(path: &Path, policy: Checksums, max_decoded: u64) -> Result<KilnFile> {
        let io = |e: std::io::Error| FormatError::new(ErrorKind::Io(e.to_string()));
        let meta = std::fs::metadata(path).map_err(io)?;
        if !meta.is_file() {
            return Err(FormatError::new(ErrorKind::NotAFile));
        }
        let file = File::open(path).map_err(io)?;
        let backing = if meta.len() < HEADER_SIZE as u64 {
            // Too short to be valid; read it so that the error can look at what is there
            // (mapping an empty file fails on some systems).
            Backing::copy_of(&std::fs::read(path).map_err(io)?)
        } else {
            // SAFETY: the map is read-only and private to this process. As with every mapped
            // reader, another process truncating or rewriting the file while it is mapped is
            // outside our control; kiln's own writer never does so (it renames a new file into
            // place instead).
            Backing::Mapped(unsafe { Mmap::map(&file) }.map_err(io)?)
        };
        Self::from_backing(backing, policy, max_decoded)
    }

    /// Validates a file held in memory (copied into aligned storage).
    pub fn from_bytes(bytes: &[u8], policy: Checksums) -> Result<KilnFile> {
        Self::from_bytes_limited(bytes, policy, DEFAULT_MAX_DECODED)
    }

    /// [`KilnFile::from_bytes`] with a limit on each compressed section's decoded size (see
    /// [`KilnFile::open_limited`]).
    pub fn from_bytes_limited(bytes: &[u8], policy: Checksums, max_decoded: u64) -> Result<KilnFile> {
        Self::from_backing(Backing::copy_of(bytes), policy, max_decoded)
    }

    fn from_backing(backing: Backing, policy: Checksums, max_decoded: u64) -> Result<KilnFile> {
        let (header, sections) = validate_layout(backing.bytes(), max_decoded)?;
        let verified = (0..sections.len()).map(|_| OnceLock::new()).collect();
        let decoded = (0..sections.len()).map(|_| OnceLock::new()).collect();
        let file = KilnFile {
            backing,
            header,
            sections,
            verified,
            decoded,
            policy,
            max_decoded,
            decode_nanos: AtomicU64::new(0),
        };
        if policy == Checksums::Eager {
            file.verify_all()?;
        }
        Ok(file)
    }

    /// The whole file.
    pub fn bytes(&self) -> &[u8] {
        self.backing.bytes()
    }

    /// The header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// Every section, in table (and file) order.
    pub fn sections(&self) -> &[Section] {
        &self.sections
    }

    /// Sections this reader skips: unknown kinds and newer versions of known ones.
    pub fn skipped(&self) -> impl Iterator<Item = &Section> {
        self.sections.iter().filter(|s| s.known.is_none())
    }

    /// The section of `kind` and `index` this reader understands, if present.
    pub fn find(&self, kind: SectionKind, index: u32) -> Option<&Section> {
        self.sections.iter().find(|s| s.entry.kind == kind && s.entry.index == index && s.known.is_some())
    }

    /// Every understood section of `kind`, in index order.
    pub fn all_of(&self, kind: SectionKind) -> Vec<&Section> {
        let mut v: Vec<&Section> =
            self.sections.iter().filter(|s| s.entry.kind == kind && s.known.is_some()).collect();
        v.sort_by_key(|s| s.entry.index);
        v
    }

    /// Verifies one section's checksum (cached).
    pub fn verify_section(&self, position: usize) -> Result<()> {
        let s = &self.sections[position];
        self.verified[position]
            .get_or_init(|| {
                let bytes = self.stored_bytes(s);
                let computed = checksum64(bytes);
                if computed == s.entry.checksum {
                    Ok(())
                } else {
                    Err(FormatError::at(
                        ErrorKind::Checksum { what: "section", stored: s.entry.checksum, computed },
                        s.entry.offset,
                    )
                    .in_section(position, s.entry.kind, s.entry.index))
                }
            })
            .clone()
    }

    /// Verifies every section's checksum, in file order; the first failure is returned.
    pub fn verify_all(&self) -> Result<()> {
        (0..self.sections.len()).try_for_each(|i| self.verify_section(i))
    }

    fn stored_bytes(&self, s: &Section) -> &[u8] {
        // In range: validate_layout checked offset + size <= file length.
        &self.bytes()[s.entry.offset as usize..(s.entry.offset + s.entry.size) as usize]
    }

    /// The decoded bytes of a section, verifying its checksum unless the policy defers it.
    /// Always borrowed: sections stored as is come from the file, compressed ones are decoded on
    /// first access and kept.
    pub fn section_bytes(&self, s: &Section) -> Result<Cow<'_, [u8]>> {
        self.decoded_bytes(s).map(Cow::Borrowed)
    }

    /// Decodes section `position` (verifying its stored checksum first unless the policy defers
    /// it) and returns its decoded length: `kiln verify` calls it for every section, so that
    /// damage behind the stored checksum (a frame that does not decode to `raw_size`) is found
    /// even in sections no content check reads.
    pub fn decode_section(&self, position: usize) -> Result<u64> {
        self.decoded_bytes(&self.sections[position]).map(|b| b.len() as u64)
    }

    /// Verifies and decodes the sections at `positions` now, on up to as many threads as the
    /// machine has, largest first (a zstd frame decodes on one thread, so the largest section
    /// bounds the wall time); later reads of them are free. Sections stored as is are only
    /// verified. Returns the first error in `positions` order.
    pub fn decode_sections(&self, positions: &[usize]) -> Result<()> {
        let known: Vec<usize> = positions.iter().copied().filter(|&p| p < self.sections.len()).collect();
        let mut largest_first = known.clone();
        largest_first.sort_by_key(|&p| std::cmp::Reverse(self.sections[p].entry.raw_size));
        // Errors stay cached in the sections' cells; reported below, in `positions` order.
        crate::parallel::on_all_cores(largest_first, |p| {
            let _ = self.decoded_bytes(&self.sections[p]);
        });
        known.into_iter().try_for_each(|p| self.decode_section(p).map(|_| ()))
    }

    /// Wall time spent decoding compressed sections so far (each is decoded once).
    pub fn decode_time(&self) -> std::time::Duration {
        std::time::Duration::from_nanos(self.decode_nanos.load(Ordering::Relaxed))
    }

    fn decoded_bytes(&self, s: &Section) -> Result<&[u8]> {
        if self.policy != Checksums::Deferred {
            self.verify_section(s.position)?;
        }
        let here =
            |e: FormatError| e.in_section(s.position, s.entry.kind, s.entry.index).or_offset(s.entry.offset);
        match Codec::from_u8(s.entry.codec) {
            Some(Codec::None) => Ok(self.stored_bytes(s)),
            Some(Codec::Zstd) => {
                let decoded = self.decoded[s.position].get_or_init(|| {
                    let t = Instant::now();
                    let d = decode_zstd(self.stored_bytes(s), s.entry.raw_size, self.max_decoded);
                    self.decode_nanos.fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
                    d
                });
                match decoded {
                    Ok(a) => Ok(a.bytes()),
                    Err(e) => Err(here(e.clone())),
                }
            }
            None => Err(here(FormatError::new(ErrorKind::UnknownCodec(s.entry.codec)))),
        }
    }

    /// The one header of a group of section kinds that come together or not at all (`kinds[0]`
    /// holds exactly one `H`): `None` when none is present; an error naming `group` when only
    /// some are, or naming the header's kind when it holds other than one header.
    pub fn group_header<H: Pod>(&self, kinds: &[SectionKind], group: &str) -> Result<Option<&H>> {
        let present = kinds.iter().filter(|&&k| self.find(k, 0).is_some()).count();
        if present == 0 {
            return Ok(None);
        }
        let names =
            || kinds.iter().map(|&k| crate::sections::info(k).map_or("?", |i| i.name)).collect::<Vec<_>>();
        if present < kinds.len() {
            return Err(FormatError::invalid(format!("{group}: {} must come together", names().join(", "))));
        }
        let header: &[H] = self.pod(kinds[0], 0)?.unwrap_or(&[]);
        match header {
            [h] => Ok(Some(h)),
            _ => Err(FormatError::invalid(format!("{} holds {} headers, not one", names()[0], header.len()))),
        }
    }

    /// A section of plain-old-data elements: zero-copy from the file when stored as is, from the
    /// cached decoded bytes when compressed. `None` if absent.
    pub fn pod<T: Pod>(&self, kind: SectionKind, index: u32) -> Result<Option<&[T]>> {
        let Some(s) = self.find(kind, index) else {
            return Ok(None);
        };
        let loc = |e: FormatError| e.in_section(s.position, kind, index).or_offset(s.entry.offset);
        let element_size = s.known.map(|k| k.element_size_at(s.entry.version));
        if element_size != Some(size_of::<T>()) {
            return Err(loc(FormatError::invalid(format!(
                "element type of {} bytes requested, the section holds {}-byte elements",
                size_of::<T>(),
                element_size.unwrap_or(0)
            ))));
        }
        let bytes = self.decoded_bytes(s).map_err(loc)?;
        bytemuck::try_cast_slice(bytes)
            .map(Some)
            .map_err(|e| loc(FormatError::invalid(format!("cannot view section as elements: {e}"))))
    }

    /// [`Self::pod`] of a section that must hold exactly `count` elements (as its manifest record
    /// or header says), checked against the table's decoded size *before* decoding
    /// ([`Self::expect_count`]). `what` names the section in the error.
    pub fn pod_exact<T: Pod>(
        &self,
        kind: SectionKind,
        index: u32,
        count: u64,
        what: &str,
    ) -> Result<Option<&[T]>> {
        self.expect_count(kind, index, count, size_of::<T>(), what)?;
        self.pod(kind, index)
    }

    /// Whether the table declares `count` elements of `element_size` bytes for section
    /// (`kind`, `index`) (absent: yes), without decoding it: a 760 KB file whose compressed
    /// section claims 4 GiB of zeros is refused without spending them.
    pub fn expect_count(
        &self,
        kind: SectionKind,
        index: u32,
        count: u64,
        element_size: usize,
        what: &str,
    ) -> Result<()> {
        let Some(s) = self.find(kind, index) else { return Ok(()) };
        if count.checked_mul(element_size as u64) != Some(s.entry.raw_size) {
            return Err(FormatError::invalid(format!(
                "{what}: the table declares {} bytes, its record {count} elements of {element_size} bytes",
                s.entry.raw_size
            ))
            .in_section(s.position, kind, index)
            .or_offset(s.entry.offset));
        }
        Ok(())
    }

    /// Decodes the manifest.
    pub fn manifest(&self) -> Result<Manifest> {
        let s =
            self.find(MANIFEST, 0).ok_or_else(|| FormatError::new(ErrorKind::MissingSection(MANIFEST)))?;
        let bytes = self.section_bytes(s)?;
        Manifest::decode(&bytes, s.entry.version)
            .map_err(|e| e.in_section(s.position, MANIFEST, 0).or_offset(s.entry.offset))
    }
}

/// Checks header, table, bounds, alignment, order, padding and lengths. Allocates only after
/// the section count has been checked against the file length.
/// `max_decoded` bounds the decoded size of compressed sections of known kinds.
fn validate_layout(file: &[u8], max_decoded: u64) -> Result<(Header, Vec<Section>)> {
    let header = Header::parse(file)?;
    let len = file.len() as u64;
    let count = header.section_count as u64;
    let table_end = count
        .checked_mul(ENTRY_SIZE as u64)
        .and_then(|t| t.checked_add(header.table_offset))
        .filter(|&end| end <= len)
        .ok_or_else(|| {
            FormatError::at(
                ErrorKind::BadField(format!(
                    "section table of {count} entries does not fit in the {len}-byte file"
                )),
                20,
            )
        })?;
    let table = &file[header.table_offset as usize..table_end as usize];
    let computed = checksum64(table);
    if computed != header.table_checksum {
        return Err(FormatError::at(
            ErrorKind::Checksum { what: "section table", stored: header.table_checksum, computed },
            header.table_offset,
        ));
    }

    let mut sections: Vec<Section> = Vec::with_capacity(count as usize);
    let mut seen = std::collections::HashSet::with_capacity(count as usize);
    let mut cursor = table_end;
    for (position, raw) in table.chunks_exact(ENTRY_SIZE).enumerate() {
        let entry = SectionEntry::from_bytes(raw);
        let entry_at = header.table_offset + (position * ENTRY_SIZE) as u64;
        let here = |kind: ErrorKind, at: u64| {
            FormatError::at(kind, at).in_section(position, entry.kind, entry.index)
        };
        let bad = |msg: String, field: u64| here(ErrorKind::BadField(msg), entry_at + field);

        if !(MIN_ALIGN_LOG2..=MAX_ALIGN_LOG2).contains(&entry.align_log2) {
            return Err(bad(
                format!(
                    "alignment 2^{} is outside 2^{MIN_ALIGN_LOG2}..=2^{MAX_ALIGN_LOG2}",
                    entry.align_log2
                ),
                7,
            ));
        }
        if entry.flags != 0 {
            return Err(bad(format!("reserved entry flags are {:#x}, must be 0", entry.flags), 12));
        }
        let expected = align_up(cursor, entry.alignment()).unwrap_or(u64::MAX);
        if entry.offset != expected {
            let why = if entry.offset < cursor {
                "overlaps the previous section or the table"
            } else if !entry.offset.is_multiple_of(entry.alignment()) {
                "is misaligned"
            } else {
                "leaves a gap after the previous section"
            };
            return Err(bad(
                format!("section offset {:#x} {why} (expected {expected:#x})", entry.offset),
                16,
            ));
        }
        let end = entry.offset.checked_add(entry.size).filter(|&e| e <= len).ok_or_else(|| {
            bad(
                format!(
                    "section of {} bytes at {:#x} runs past the end of the {len}-byte file",
                    entry.size, entry.offset
                ),
                24,
            )
        })?;
        if let Some(i) = file[cursor as usize..entry.offset as usize].iter().position(|&b| b != 0) {
            return Err(FormatError::at(
                ErrorKind::NonZeroPadding(file[cursor as usize + i]),
                cursor + i as u64,
            )
            .in_section(position, entry.kind, entry.index));
        }
        let codec = Codec::from_u8(entry.codec);
        if codec == Some(Codec::None) && entry.raw_size != entry.size {
            return Err(bad(
                format!(
                    "codec none but decoded size {} differs from stored size {}",
                    entry.raw_size, entry.size
                ),
                32,
            ));
        }

        let known = sections::info(entry.kind).filter(|k| entry.version <= k.version || k.kind == MANIFEST);
        if let Some(k) = known {
            if codec.is_none() {
                return Err(here(ErrorKind::UnknownCodec(entry.codec), entry_at + 6));
            }
            // Before anything sized by it is allocated (decoding allocates exactly raw_size).
            if codec == Some(Codec::Zstd) && entry.raw_size > max_decoded {
                return Err(here(
                    ErrorKind::DecodedTooLarge { declared: entry.raw_size, limit: max_decoded },
                    entry_at + 32,
                ));
            }
            if entry.version == 0 {
                return Err(bad("section version 0 is not defined".into(), 4));
            }
            if !k.indexed && entry.index != 0 {
                return Err(bad(
                    format!("{} is not an indexed kind but has index {}", k.name, entry.index),
                    8,
                ));
            }
            let element_size = k.element_size_at(entry.version);
            if !entry.raw_size.is_multiple_of(element_size as u64) {
                return Err(bad(
                    format!(
                        "{} section of {} bytes is not a whole number of {}-byte elements",
                        k.name, entry.raw_size, element_size
                    ),
                    32,
                ));
            }
        }
        if !seen.insert((entry.kind, entry.index)) {
            return Err(here(ErrorKind::DuplicateSection(entry.kind, entry.index), entry_at));
        }
        sections.push(Section { position, entry, known });
        cursor = end;
    }
    if cursor != len {
        return Err(FormatError::at(
            ErrorKind::BadField(format!(
                "{} bytes after the last section belong to no section",
                len - cursor
            )),
            cursor,
        ));
    }
    for k in sections::KNOWN.iter().filter(|k| k.required) {
        if !sections.iter().any(|s| s.entry.kind == k.kind) {
            return Err(FormatError::new(ErrorKind::MissingSection(k.kind)));
        }
    }
    Ok((header, sections))
}
