//! Reading: validate everything about the layout before handing out any byte.

use std::borrow::Cow;
use std::fs::File;
use std::path::Path;
use std::sync::OnceLock;

use bytemuck::Pod;
use memmap2::Mmap;

use crate::checksum::checksum64;
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

/// 64-byte aligned owned storage, so that sections copied into memory keep the alignment that a
/// memory map gives for free.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Block([u8; 64]);

enum Backing {
    Mapped(Mmap),
    Owned { blocks: Vec<Block>, len: usize },
}

impl Backing {
    fn bytes(&self) -> &[u8] {
        match self {
            Backing::Mapped(m) => m,
            Backing::Owned { blocks, len } => {
                // SAFETY: `Block` is 64 plain bytes with no padding, so a slice of blocks is a
                // slice of `64 * blocks.len()` initialised bytes; `len` never exceeds that.
                let all =
                    unsafe { std::slice::from_raw_parts(blocks.as_ptr().cast::<u8>(), blocks.len() * 64) };
                &all[..*len]
            }
        }
    }

    fn copy_of(bytes: &[u8]) -> Backing {
        let mut blocks = vec![Block([0; 64]); bytes.len().div_ceil(64)];
        for (block, chunk) in blocks.iter_mut().zip(bytes.chunks(64)) {
            block.0[..chunk.len()].copy_from_slice(chunk);
        }
        Backing::Owned { blocks, len: bytes.len() }
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
    policy: Checksums,
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
        Self::from_backing(backing, policy)
    }

    /// Validates a file held in memory (copied into aligned storage).
    pub fn from_bytes(bytes: &[u8], policy: Checksums) -> Result<KilnFile> {
        Self::from_backing(Backing::copy_of(bytes), policy)
    }

    fn from_backing(backing: Backing, policy: Checksums) -> Result<KilnFile> {
        let (header, sections) = validate_layout(backing.bytes())?;
        let verified = (0..sections.len()).map(|_| OnceLock::new()).collect();
        let file = KilnFile { backing, header, sections, verified, policy };
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
    pub fn section_bytes(&self, s: &Section) -> Result<Cow<'_, [u8]>> {
        if self.policy != Checksums::Deferred {
            self.verify_section(s.position)?;
        }
        match Codec::from_u8(s.entry.codec) {
            Some(Codec::None) => Ok(Cow::Borrowed(self.stored_bytes(s))),
            None => Err(FormatError::at(ErrorKind::UnknownCodec(s.entry.codec), s.entry.offset).in_section(
                s.position,
                s.entry.kind,
                s.entry.index,
            )),
        }
    }

    /// A section of plain-old-data elements, zero-copy. `None` if absent.
    pub fn pod<T: Pod>(&self, kind: SectionKind, index: u32) -> Result<Option<&[T]>> {
        let Some(s) = self.find(kind, index) else {
            return Ok(None);
        };
        let loc = |e: FormatError| e.in_section(s.position, kind, index).or_offset(s.entry.offset);
        if s.known.map(|k| k.element_size) != Some(size_of::<T>()) {
            return Err(loc(FormatError::invalid(format!(
                "element type of {} bytes requested, the section holds {}-byte elements",
                size_of::<T>(),
                s.known.map_or(0, |k| k.element_size)
            ))));
        }
        match self.section_bytes(s).map_err(loc)? {
            Cow::Borrowed(bytes) => bytemuck::try_cast_slice(bytes)
                .map(Some)
                .map_err(|e| loc(FormatError::invalid(format!("cannot view section as elements: {e}")))),
            // No compressing codec exists yet; when one does, decoded sections are cached.
            Cow::Owned(_) => Err(loc(FormatError::invalid("compressed POD sections are not supported"))),
        }
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
fn validate_layout(file: &[u8]) -> Result<(Header, Vec<Section>)> {
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
            if entry.version == 0 {
                return Err(bad("section version 0 is not defined".into(), 4));
            }
            if !k.indexed && entry.index != 0 {
                return Err(bad(
                    format!("{} is not an indexed kind but has index {}", k.name, entry.index),
                    8,
                ));
            }
            if !entry.raw_size.is_multiple_of(k.element_size as u64) {
                return Err(bad(
                    format!(
                        "{} section of {} bytes is not a whole number of {}-byte elements",
                        k.name, entry.raw_size, k.element_size
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
