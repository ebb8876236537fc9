//! The `.kiln` container: byte layout, reader, writer and validation.
//!
//! A `.kiln` file is a 64-byte header, a table of 64-byte section entries and the sections,
//! each 64-byte aligned, checksummed (XXH3-64) and tagged with the content hash of what produced
//! it. Every byte is covered by a checksum or must be zero. `FORMAT.md` beside this crate is the
//! specification; this crate is its reference implementation.
//!
//! ```
//! use kiln_format::{Checksums, ContentHash, FileWriter, KilnFile, Manifest};
//!
//! let manifest = Manifest { scene_name: "empty".into(), ..Default::default() };
//! let bytes = FileWriter::new().manifest(&manifest, ContentHash::of(b"settings")).unwrap().to_bytes().unwrap();
//! let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
//! assert_eq!(file.manifest().unwrap(), manifest);
//! ```
#![deny(missing_docs)]

#[cfg(target_endian = "big")]
compile_error!("kiln-format reads sections zero-copy and supports little-endian hosts only");

pub mod checksum;
pub mod codec;
pub mod environment;
pub mod error;
pub mod gpu;
pub mod header;
pub mod linespace;
pub mod manifest;
mod parallel;
pub mod probes;
pub mod projection;
pub mod query;
pub mod read;
pub mod readers;
pub mod scene;
pub mod sections;
pub mod table;
pub mod write;

pub use checksum::{ContentHash, ContentHasher};
pub use error::{ErrorKind, FormatError, Result};
pub use manifest::Manifest;
pub use read::{Checksums, KilnFile, Section};
pub use scene::SceneView;
pub use table::{SectionEntry, SectionKind};
pub use write::{Compression, DEFAULT_MIN_SAVING, FileWriter, WriteError};
