//! Errors of reading and writing `.kiln` files.
//!
//! Every error says what is wrong and, where the file is at fault, where: the section (table
//! position, kind and index) and the byte offset in the file. `verify` prints exactly this line.

use std::fmt;

use crate::table::SectionKind;

/// Where in a file an error was found.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Location {
    /// Position in the section table, kind and index of the section concerned, if any.
    pub section: Option<(usize, SectionKind, u32)>,
    /// Absolute byte offset in the file, if known.
    pub offset: Option<u64>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.section, self.offset) {
            (Some((pos, kind, index)), Some(off)) => {
                write!(f, "section {pos} ({kind}#{index}) at offset {off:#x}")
            }
            (Some((pos, kind, index)), None) => write!(f, "section {pos} ({kind}#{index})"),
            (None, Some(off)) => write!(f, "offset {off:#x}"),
            (None, None) => write!(f, "file"),
        }
    }
}

/// What went wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The OS refused to open, map or read the file.
    #[error("cannot read file: {0}")]
    Io(String),
    /// The path names a directory or another non-regular file.
    #[error("not a regular file")]
    NotAFile,
    /// Shorter than a header.
    #[error("file is {0} bytes long, shorter than the 64-byte kiln header (empty or truncated)")]
    TooShort(u64),
    /// Magic mismatch; the message guesses at the cause.
    #[error("{0}")]
    BadMagic(&'static str),
    /// Another major version.
    #[error(
        "file is kiln format {file_major}.{file_minor}; this reader reads format {reader_major}.x \
         (up to {reader_major}.{reader_minor}): use a kiln of major version {file_major}, or recompile the scene"
    )]
    UnsupportedVersion {
        /// Major version found in the file.
        file_major: u16,
        /// Minor version found in the file.
        file_minor: u16,
        /// Major version this reader implements.
        reader_major: u16,
        /// Newest minor version this reader knows.
        reader_minor: u16,
    },
    /// A header or table field has an impossible value.
    #[error("{0}")]
    BadField(String),
    /// Header length field differs from the real length.
    #[error("header says the file is {expected} bytes but it is {actual} bytes ({})",
        if actual < expected { "truncated" } else { "trailing bytes after the last section" })]
    SizeMismatch {
        /// Length recorded in the header.
        expected: u64,
        /// Length of the file on disk.
        actual: u64,
    },
    /// A checksum did not match its bytes.
    #[error(
        "{what} checksum mismatch: stored {stored:#018x}, computed {computed:#018x} (the bytes are damaged)"
    )]
    Checksum {
        /// Which checksum: "header", "section table" or "section".
        what: &'static str,
        /// The stored value.
        stored: u64,
        /// The value computed over the bytes.
        computed: u64,
    },
    /// A padding byte that must be zero is not.
    #[error("padding byte is {0:#04x}, must be zero")]
    NonZeroPadding(u8),
    /// A section uses a codec this reader cannot decode.
    #[error("codec {0} is unknown to this reader")]
    UnknownCodec(u8),
    /// A compressed section's declared decoded size is above what this reader allows; refused
    /// before anything of that size is allocated.
    #[error(
        "section decodes to {declared} bytes, more than this reader's limit of {limit} bytes per \
         section (a damaged table, or a file made for a reader with a higher limit)"
    )]
    DecodedTooLarge {
        /// `raw_size` from the table.
        declared: u64,
        /// The reader's limit.
        limit: u64,
    },
    /// A compressed section does not decode to what its table entry declares.
    #[error("compressed section cannot be decoded: {0}")]
    Decode(String),
    /// A required section is missing.
    #[error("required section {0} is missing")]
    MissingSection(SectionKind),
    /// The same (kind, index) twice.
    #[error("duplicate section {0}#{1}")]
    DuplicateSection(SectionKind, u32),
    /// The manifest could not be decoded.
    #[error("manifest cannot be decoded: {0}")]
    Manifest(String),
    /// A section's contents break an invariant (length, index range, cross-reference).
    #[error("{0}")]
    Invalid(String),
}

/// An error with its location.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FormatError {
    /// What went wrong.
    pub kind: ErrorKind,
    /// Where.
    pub location: Location,
}

impl FormatError {
    /// An error at no particular place.
    pub fn new(kind: ErrorKind) -> Self {
        Self { kind, location: Location::default() }
    }

    /// An error at a byte offset.
    pub fn at(kind: ErrorKind, offset: u64) -> Self {
        Self { kind, location: Location { section: None, offset: Some(offset) } }
    }

    /// Attaches a section to the location (keeping an offset already there).
    pub fn in_section(mut self, position: usize, kind: SectionKind, index: u32) -> Self {
        self.location.section = Some((position, kind, index));
        self
    }

    /// Sets the offset if none is set yet.
    pub fn or_offset(mut self, offset: u64) -> Self {
        self.location.offset.get_or_insert(offset);
        self
    }

    /// Shorthand for an `Invalid` error.
    pub fn invalid(msg: impl Into<String>) -> Self {
        Self::new(ErrorKind::Invalid(msg.into()))
    }

    /// Whether the error is a refusal of an incompatible version (not damage).
    pub fn is_unsupported(&self) -> bool {
        matches!(self.kind, ErrorKind::UnsupportedVersion { .. } | ErrorKind::UnknownCodec(_))
    }
}

impl fmt::Display for FormatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.location == Location::default() {
            write!(f, "{}", self.kind)
        } else {
            write!(f, "{}: {}", self.location, self.kind)
        }
    }
}

impl std::error::Error for FormatError {}

/// Result alias of this crate.
pub type Result<T, E = FormatError> = std::result::Result<T, E>;
