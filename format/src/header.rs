//! The fixed 64-byte file header.
//!
//! Bytes 0..12 (magic and version) keep their meaning in every major version, so that any reader
//! can say which version a file is before it trusts anything else. See `FORMAT.md`, "Header".

use crate::checksum::checksum64;
use crate::error::{ErrorKind, FormatError, Result};

/// PNG-style signature: a high-bit byte (7-bit transfers), the name, CR LF (line-ending
/// conversion), Ctrl-Z (DOS `type`) and LF (LF to CRLF conversion).
pub const MAGIC: [u8; 8] = [0x89, b'K', b'L', b'N', b'\r', b'\n', 0x1a, b'\n'];
/// Major version this crate reads and writes.
pub const VERSION_MAJOR: u16 = 1;
/// Newest minor version this crate knows (and writes).
pub const VERSION_MINOR: u16 = 10;
/// Size of the header in bytes.
pub const HEADER_SIZE: usize = 64;
/// Flag bits 0..16 must be understood by a reader; none are defined in 1.0.
pub const REQUIRED_FLAGS_MASK: u32 = 0x0000_ffff;
/// Flag bits this reader understands.
pub const KNOWN_FLAGS: u32 = 0;

/// The decoded header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header {
    /// Format major version.
    pub version_major: u16,
    /// Format minor version.
    pub version_minor: u16,
    /// File flags (see [`REQUIRED_FLAGS_MASK`]).
    pub flags: u32,
    /// Number of entries in the section table.
    pub section_count: u32,
    /// Offset of the section table (64 in format 1).
    pub table_offset: u64,
    /// Total length of the file.
    pub file_size: u64,
    /// xxh3-64 of the section table bytes.
    pub table_checksum: u64,
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}
fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}
pub(crate) fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

impl Header {
    /// Serialises the header, computing its own checksum.
    pub fn to_bytes(&self) -> [u8; HEADER_SIZE] {
        let mut b = [0u8; HEADER_SIZE];
        b[0..8].copy_from_slice(&MAGIC);
        b[8..10].copy_from_slice(&self.version_major.to_le_bytes());
        b[10..12].copy_from_slice(&self.version_minor.to_le_bytes());
        b[12..16].copy_from_slice(&self.flags.to_le_bytes());
        b[16..20].copy_from_slice(&(HEADER_SIZE as u32).to_le_bytes());
        b[20..24].copy_from_slice(&self.section_count.to_le_bytes());
        b[24..32].copy_from_slice(&self.table_offset.to_le_bytes());
        b[32..40].copy_from_slice(&self.file_size.to_le_bytes());
        b[40..48].copy_from_slice(&self.table_checksum.to_le_bytes());
        // 48..56 reserved, zero.
        let sum = checksum64(&b[0..56]);
        b[56..64].copy_from_slice(&sum.to_le_bytes());
        b
    }

    /// Parses and checks the header at the start of `file`; `file.len()` is the real file length.
    pub fn parse(file: &[u8]) -> Result<Header> {
        let len = file.len() as u64;
        // Judge the magic on whatever prefix exists, so that a truncated text file is still
        // reported as "not a kiln file" rather than as "too short".
        let prefix = &file[..file.len().min(8)];
        if prefix != &MAGIC[..prefix.len()] || prefix.is_empty() {
            return Err(FormatError::at(ErrorKind::BadMagic(diagnose_magic(file)), 0));
        }
        if file.len() < HEADER_SIZE {
            return Err(FormatError::at(ErrorKind::TooShort(len), 0));
        }
        let b = &file[..HEADER_SIZE];
        let version_major = u16_at(b, 8);
        let version_minor = u16_at(b, 10);
        if version_major != VERSION_MAJOR {
            return Err(FormatError::at(
                ErrorKind::UnsupportedVersion {
                    file_major: version_major,
                    file_minor: version_minor,
                    reader_major: VERSION_MAJOR,
                    reader_minor: VERSION_MINOR,
                },
                8,
            ));
        }
        let stored = u64_at(b, 56);
        let computed = checksum64(&b[0..56]);
        if stored != computed {
            return Err(FormatError::at(ErrorKind::Checksum { what: "header", stored, computed }, 56));
        }
        let flags = u32_at(b, 12);
        let header_size = u32_at(b, 16);
        let header = Header {
            version_major,
            version_minor,
            flags,
            section_count: u32_at(b, 20),
            table_offset: u64_at(b, 24),
            file_size: u64_at(b, 32),
            table_checksum: u64_at(b, 40),
        };
        let bad = |msg: String, at: u64| Err(FormatError::at(ErrorKind::BadField(msg), at));
        if header_size as usize != HEADER_SIZE {
            return bad(format!("header size is {header_size}, must be {HEADER_SIZE}"), 16);
        }
        let unknown_required = flags & REQUIRED_FLAGS_MASK & !KNOWN_FLAGS;
        if unknown_required != 0 {
            return bad(
                format!("file needs features this reader lacks (required flag bits {unknown_required:#06x})"),
                12,
            );
        }
        if u64_at(b, 48) != 0 {
            return bad("reserved header bytes 48..56 are not zero".into(), 48);
        }
        if header.table_offset != HEADER_SIZE as u64 {
            return bad(
                format!("section table offset is {}, must be {HEADER_SIZE}", header.table_offset),
                24,
            );
        }
        if header.file_size != len {
            return Err(FormatError::at(
                ErrorKind::SizeMismatch { expected: header.file_size, actual: len },
                32,
            ));
        }
        Ok(header)
    }
}

/// Explains a magic mismatch: the usual transfer accidents first.
fn diagnose_magic(file: &[u8]) -> &'static str {
    if file.is_empty() {
        return "file is empty (0 bytes): not a kiln file";
    }
    if file.starts_with(&[0x89, b'K', b'L', b'N', b'\n']) {
        return "not a kiln file: its signature lost a CR (CRLF was converted to LF by a text-mode transfer)";
    }
    if file.starts_with(&[0x89, b'K', b'L', b'N', b'\r', b'\n', 0x1a, b'\r', b'\n']) {
        return "not a kiln file: its signature gained a CR (LF was converted to CRLF by a text-mode transfer)";
    }
    if file.len() >= 4 && file[1..4] == *b"KLN" && file[0] == 0x09 {
        return "not a kiln file: the high bit of byte 0 was stripped (7-bit transfer)";
    }
    if file.starts_with(b"glTF") {
        return "this is a binary glTF (.glb), not a kiln file: compile it with `kiln compile`";
    }
    if file.iter().take(64).all(|&c| c == b'\t' || c == b'\n' || c == b'\r' || (0x20..0x7f).contains(&c)) {
        return "not a kiln file: it looks like text";
    }
    "not a kiln file: its first bytes are not the kiln signature"
}
