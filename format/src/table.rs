//! The section table: one 64-byte entry per section, in file order.

use std::fmt;

use crate::checksum::ContentHash;
use crate::header::u64_at;

/// Size of one table entry in bytes.
pub const ENTRY_SIZE: usize = 64;
/// Smallest allowed section alignment (log2): 64 bytes, a cache line and more than any GPU
/// element type needs.
pub const MIN_ALIGN_LOG2: u8 = 6;
/// Largest allowed section alignment (log2): 64 KiB, enough for any page size.
pub const MAX_ALIGN_LOG2: u8 = 16;

/// A section kind: four ASCII bytes (a FourCC), compared as bytes.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SectionKind(pub [u8; 4]);

impl SectionKind {
    /// The kind as text when it is printable ASCII, else as hex.
    pub fn name(&self) -> String {
        if self.0.iter().all(|c| c.is_ascii_graphic()) {
            String::from_utf8_lossy(&self.0).into_owned()
        } else {
            format!("0x{:08x}", u32::from_le_bytes(self.0))
        }
    }
}

impl fmt::Display for SectionKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

impl fmt::Debug for SectionKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "SectionKind({})", self.name())
    }
}

/// How a section's bytes are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Codec {
    /// Stored as is: the bytes in the file are the section (zero-copy).
    None = 0,
    /// One zstd frame (RFC 8878) that decodes to exactly `raw_size` bytes (format 1.2).
    Zstd = 1,
}

impl Codec {
    /// The codec with this number, if this reader knows it.
    pub fn from_u8(v: u8) -> Option<Codec> {
        match v {
            0 => Some(Codec::None),
            1 => Some(Codec::Zstd),
            _ => None,
        }
    }

    /// Its name in `inspect` output.
    pub fn name(self) -> &'static str {
        match self {
            Codec::None => "none",
            Codec::Zstd => "zstd",
        }
    }
}

/// One entry of the section table, as stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SectionEntry {
    /// What the section holds.
    pub kind: SectionKind,
    /// Version of that kind's layout.
    pub version: u16,
    /// Codec number (see [`Codec`]); kept raw so that unknown codecs can be reported.
    pub codec: u8,
    /// log2 of the alignment of `offset`.
    pub align_log2: u8,
    /// Instance number among sections of the same kind (e.g. texture 3).
    pub index: u32,
    /// Reserved, zero in format 1.0.
    pub flags: u32,
    /// Absolute byte offset of the section.
    pub offset: u64,
    /// Stored length in bytes.
    pub size: u64,
    /// Decoded length in bytes (equals `size` for codec none).
    pub raw_size: u64,
    /// XXH3-64 of the stored bytes.
    pub checksum: u64,
    /// Hash of the inputs and settings that produced the section.
    pub content_hash: ContentHash,
}

impl SectionEntry {
    /// Serialises the entry.
    pub fn to_bytes(&self) -> [u8; ENTRY_SIZE] {
        let mut b = [0u8; ENTRY_SIZE];
        b[0..4].copy_from_slice(&self.kind.0);
        b[4..6].copy_from_slice(&self.version.to_le_bytes());
        b[6] = self.codec;
        b[7] = self.align_log2;
        b[8..12].copy_from_slice(&self.index.to_le_bytes());
        b[12..16].copy_from_slice(&self.flags.to_le_bytes());
        b[16..24].copy_from_slice(&self.offset.to_le_bytes());
        b[24..32].copy_from_slice(&self.size.to_le_bytes());
        b[32..40].copy_from_slice(&self.raw_size.to_le_bytes());
        b[40..48].copy_from_slice(&self.checksum.to_le_bytes());
        b[48..64].copy_from_slice(&self.content_hash.0);
        b
    }

    /// Decodes an entry; the caller passes exactly [`ENTRY_SIZE`] bytes. Nothing is checked here.
    pub fn from_bytes(b: &[u8]) -> SectionEntry {
        debug_assert_eq!(b.len(), ENTRY_SIZE);
        let mut hash = [0u8; 16];
        hash.copy_from_slice(&b[48..64]);
        SectionEntry {
            kind: SectionKind([b[0], b[1], b[2], b[3]]),
            version: u16::from_le_bytes([b[4], b[5]]),
            codec: b[6],
            align_log2: b[7],
            index: u32::from_le_bytes([b[8], b[9], b[10], b[11]]),
            flags: u32::from_le_bytes([b[12], b[13], b[14], b[15]]),
            offset: u64_at(b, 16),
            size: u64_at(b, 24),
            raw_size: u64_at(b, 32),
            checksum: u64_at(b, 40),
            content_hash: ContentHash(hash),
        }
    }

    /// The alignment in bytes.
    pub fn alignment(&self) -> u64 {
        1u64 << self.align_log2.min(63)
    }
}

/// Rounds `x` up to a multiple of the power of two `align`; `None` on overflow.
pub fn align_up(x: u64, align: u64) -> Option<u64> {
    debug_assert!(align.is_power_of_two());
    x.checked_add(align - 1).map(|v| v & !(align - 1))
}
