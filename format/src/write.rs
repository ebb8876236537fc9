//! Writing: a deterministic layout, written atomically.

use std::borrow::Cow;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use bytemuck::Pod;

use crate::checksum::{ContentHash, checksum64};
use crate::header::{HEADER_SIZE, Header, VERSION_MAJOR, VERSION_MINOR};
use crate::manifest::{MANIFEST_VERSION, Manifest};
use crate::sections::{self, MANIFEST};
use crate::table::{Codec, ENTRY_SIZE, MIN_ALIGN_LOG2, SectionEntry, SectionKind, align_up};

/// Why a file could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// The same kind and index were added twice.
    #[error("section {0}#{1} added twice")]
    Duplicate(SectionKind, u32),
    /// A section's length is not a whole number of its kind's elements.
    #[error("section {kind} has {len} bytes, not a multiple of its {element}-byte elements")]
    Ragged {
        /// Kind.
        kind: SectionKind,
        /// Length given.
        len: usize,
        /// Element size of the kind.
        element: usize,
    },
    /// The zstd library refused to compress (out of memory).
    #[error("cannot compress section {kind}#{index}: {source}")]
    Compress {
        /// Kind.
        kind: SectionKind,
        /// Index.
        index: u32,
        /// Cause.
        source: io::Error,
    },
    /// No manifest was added.
    #[error("a kiln file needs a manifest section")]
    NoManifest,
    /// The operating system refused.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// File concerned.
        path: PathBuf,
        /// Cause.
        source: io::Error,
    },
}

struct Pending<'a> {
    kind: SectionKind,
    index: u32,
    version: u16,
    align_log2: u8,
    bytes: Cow<'a, [u8]>,
    content_hash: ContentHash,
    /// The zstd frame, when the section is compressed (set by `layout`).
    compressed: Option<Vec<u8>>,
}

impl Pending<'_> {
    fn stored(&self) -> &[u8] {
        self.compressed.as_deref().unwrap_or(&self.bytes)
    }
}

/// Which sections a writer compresses (with zstd, FORMAT.md "Codecs"). Whatever the choice, a
/// section is stored as is when its zstd frame would not be smaller.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Compression {
    /// Every section stored as is.
    #[default]
    None,
    /// Every section whose frame saves at least [`DEFAULT_MIN_SAVING`] of it. Sections that
    /// barely shrink stay as is (zero-copy); the player decodes the others on all cores while
    /// the driver creates the device, where it costs no time to the first frame.
    Default,
    /// Every section that shrinks at all.
    All,
}

/// The fraction of a section that [`Compression::Default`] must save to store it compressed:
/// below it, a zero-copy read is worth more than the bytes.
pub const DEFAULT_MIN_SAVING: f64 = 0.125;

/// Sections at least this large are compressed on every core, one after another (see
/// `Writer::compress`): four of zstd's jobs at the pinned level (16 MiB each), below which
/// compressing sections side by side keeps the cores as busy.
const LARGE_SECTION: usize = 64 << 20;

impl Compression {
    /// Whether a section is to be compressed at all.
    pub fn compresses(self) -> bool {
        self != Compression::None
    }

    /// Whether a frame of `frame` bytes is kept for a section of `raw` bytes.
    pub fn keeps(self, frame: usize, raw: usize) -> bool {
        match self {
            Compression::None => false,
            Compression::Default => (frame as f64) <= raw as f64 * (1.0 - DEFAULT_MIN_SAVING),
            Compression::All => frame < raw,
        }
    }
}

/// Collects sections and writes them as one `.kiln` file.
///
/// The output depends only on the sections added, never on the order they were added in: they
/// are laid out in streaming order (see [`sections::KNOWN`]), then by kind, then by index.
#[derive(Default)]
pub struct FileWriter<'a> {
    pending: Vec<Pending<'a>>,
    compression: Compression,
    /// Threads that compress (`None`: one per core).
    threads: Option<usize>,
}

impl std::fmt::Debug for FileWriter<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FileWriter").field("sections", &self.pending.len()).finish()
    }
}

impl<'a> FileWriter<'a> {
    /// An empty writer.
    pub fn new() -> Self {
        Self::default()
    }

    /// Compresses on at most `threads` threads (at least one; one per core unless called). The
    /// bytes are the same for every count.
    pub fn threads(&mut self, threads: usize) -> &mut Self {
        self.threads = Some(threads.max(1));
        self
    }

    /// Chooses which sections are compressed (none unless called).
    pub fn compression(&mut self, compression: Compression) -> &mut Self {
        self.compression = compression;
        self
    }

    /// Adds the manifest.
    pub fn manifest(
        &mut self,
        manifest: &Manifest,
        content_hash: ContentHash,
    ) -> Result<&mut Self, WriteError> {
        self.raw(MANIFEST, 0, MANIFEST_VERSION, manifest.encode(), content_hash)
    }

    /// Adds a POD section of a known kind, at that kind's current version.
    pub fn pod<T: Pod>(
        &mut self,
        kind: SectionKind,
        index: u32,
        elements: &'a [T],
        content_hash: ContentHash,
    ) -> Result<&mut Self, WriteError> {
        self.bytes(kind, index, bytemuck::cast_slice(elements), content_hash)
    }

    /// Adds raw bytes of a known kind, at that kind's current version.
    pub fn bytes(
        &mut self,
        kind: SectionKind,
        index: u32,
        bytes: impl Into<Cow<'a, [u8]>>,
        content_hash: ContentHash,
    ) -> Result<&mut Self, WriteError> {
        let version = sections::info(kind).map_or(1, |k| k.version);
        self.raw(kind, index, version, bytes, content_hash)
    }

    /// Adds a section of any kind and version (also kinds this crate does not know).
    pub fn raw(
        &mut self,
        kind: SectionKind,
        index: u32,
        version: u16,
        bytes: impl Into<Cow<'a, [u8]>>,
        content_hash: ContentHash,
    ) -> Result<&mut Self, WriteError> {
        let bytes = bytes.into();
        if let Some(k) = sections::info(kind)
            && version <= k.version
            && bytes.len() % k.element_size_at(version) != 0
        {
            return Err(WriteError::Ragged { kind, len: bytes.len(), element: k.element_size_at(version) });
        }
        if self.pending.iter().any(|p| p.kind == kind && p.index == index) {
            return Err(WriteError::Duplicate(kind, index));
        }
        self.pending.push(Pending {
            kind,
            index,
            version,
            align_log2: MIN_ALIGN_LOG2,
            bytes,
            content_hash,
            compressed: None,
        });
        Ok(self)
    }

    /// Computes header and table. Sorting here makes the layout independent of insertion order.
    fn layout(&mut self) -> Result<(Header, Vec<SectionEntry>), WriteError> {
        if !self.pending.iter().any(|p| p.kind == MANIFEST) {
            return Err(WriteError::NoManifest);
        }
        self.pending.sort_by_key(|p| (sections::stream_rank(p.kind), p.kind, p.index));
        self.compress()?;
        let mut cursor = (HEADER_SIZE + ENTRY_SIZE * self.pending.len()) as u64;
        let entries: Vec<SectionEntry> = self
            .pending
            .iter()
            .map(|p| {
                let align = 1u64 << p.align_log2;
                let offset = align_up(cursor, align).expect("file offsets fit in u64");
                let stored = p.stored();
                cursor = offset + stored.len() as u64;
                SectionEntry {
                    kind: p.kind,
                    version: p.version,
                    codec: if p.compressed.is_some() { Codec::Zstd } else { Codec::None } as u8,
                    align_log2: p.align_log2,
                    index: p.index,
                    flags: 0,
                    offset,
                    size: stored.len() as u64,
                    raw_size: p.bytes.len() as u64,
                    checksum: checksum64(stored),
                    content_hash: p.content_hash,
                }
            })
            .collect();
        let table: Vec<u8> = entries.iter().flat_map(|e| e.to_bytes()).collect();
        let header = Header {
            version_major: VERSION_MAJOR,
            version_minor: VERSION_MINOR,
            flags: 0,
            section_count: entries.len() as u32,
            table_offset: HEADER_SIZE as u64,
            file_size: cursor,
            table_checksum: checksum64(&table),
        };
        Ok((header, entries))
    }

    /// Compresses the sections the policy selects, on the writer's threads: the
    /// small ones side by side, a thread each, then each large one on all the threads (zstd's
    /// jobs; one section of PNMT records can be most of a file, and one thread took 14 s over
    /// 2.7 GB). The bytes do not depend on the thread count ([`crate::codec::compress_zstd`]).
    /// Keeps a frame only when the policy finds it small enough.
    fn compress(&mut self) -> Result<(), WriteError> {
        let policy = self.compression;
        let (large, small): (Vec<&mut Pending<'a>>, Vec<&mut Pending<'a>>) = self
            .pending
            .iter_mut()
            .filter(|p| p.compressed.is_none() && !p.bytes.is_empty() && policy.compresses())
            .partition(|p| p.bytes.len() >= LARGE_SECTION);
        let compress = |p: &mut Pending<'a>, workers: u32| {
            let frame = crate::codec::compress_zstd(&p.bytes, workers)
                .map_err(|source| WriteError::Compress { kind: p.kind, index: p.index, source })?;
            if policy.keeps(frame.len(), p.bytes.len()) {
                p.compressed = Some(frame);
            }
            Ok(())
        };
        let threads = self.threads.unwrap_or_else(crate::parallel::cores);
        let results = crate::parallel::on_threads(threads, small, |p| compress(p, 1));
        results.into_iter().collect::<Result<(), WriteError>>()?;
        large.into_iter().try_for_each(|p| compress(p, threads as u32))
    }

    /// Writes the file to `out`; returns its length.
    pub fn write_to(&mut self, out: &mut dyn Write) -> Result<u64, WriteError> {
        let (header, entries) = self.layout()?;
        let io = |source| WriteError::Io { path: PathBuf::from("<stream>"), source };
        out.write_all(&header.to_bytes()).map_err(io)?;
        for e in &entries {
            out.write_all(&e.to_bytes()).map_err(io)?;
        }
        let mut cursor = (HEADER_SIZE + ENTRY_SIZE * entries.len()) as u64;
        let zeros = [0u8; 1 << 16];
        for (e, p) in entries.iter().zip(&self.pending) {
            out.write_all(&zeros[..(e.offset - cursor) as usize]).map_err(io)?;
            out.write_all(p.stored()).map_err(io)?;
            cursor = e.offset + e.size;
        }
        Ok(header.file_size)
    }

    /// The whole file in memory.
    pub fn to_bytes(&mut self) -> Result<Vec<u8>, WriteError> {
        let mut v = Vec::new();
        self.write_to(&mut v)?;
        Ok(v)
    }

    /// Writes `path` atomically: a temporary file in the same directory is written, flushed to
    /// disk and renamed over `path`, and the directory is synced. A crash or error at any point
    /// leaves an earlier `path` intact (a stray `.*.kiln-tmp*` file may remain after a crash).
    pub fn write_atomic(&mut self, path: &Path) -> Result<u64, WriteError> {
        let err = |source| WriteError::Io { path: path.to_path_buf(), source };
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let prefix = format!(".{name}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".kiln-tmp");
        // Temporary files are private by default; the result should get the permissions of
        // any file the user creates (0666 less the umask).
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let tmp = builder.tempfile_in(dir).map_err(err)?;
        let mut buf = io::BufWriter::with_capacity(1 << 20, tmp);
        let len = self.write_to(&mut buf).map_err(|e| match e {
            WriteError::Io { source, .. } => err(source),
            other => other,
        })?;
        let tmp = buf.into_inner().map_err(|e| err(e.into_error()))?;
        tmp.as_file().sync_all().map_err(err)?;
        tmp.persist(path).map_err(|e| err(e.error))?;
        // Make the rename itself durable. Directories cannot be opened for syncing everywhere;
        // where they cannot, the rename is as durable as the platform makes it.
        if let Ok(d) = std::fs::File::open(dir) {
            let _ = d.sync_all();
        }
        Ok(len)
    }
}
