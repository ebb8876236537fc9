//! The stage cache (`kiln compile --cache DIR`, or `KILN_CACHE`): each bake stage's output kept
//! under the content hash of what the stage reads, so that a compile whose inputs changed only in
//! part re-bakes only the stages that read the changed part.
//!
//! The layout is a plain content-addressed directory (docs/compiler.md, "Stage cache"):
//!
//! ```text
//! DIR/CACHEDIR.TAG           marks the directory as a cache for backup tools
//! DIR/<stage>/<key>.kiln     one entry: a .kiln container (header, table, checksummed sections)
//! DIR/tmp/                   entries being written; renamed into place when complete
//! ```
//!
//! `<key>` is the 32 hex digits of the stage's key (XXH3-128 of the cache layout version, the
//! compiler's version and algorithm version, the stage's name, the settings it reads and the data
//! it reads). An entry holds the stage's sections with their kinds and indices, a manifest with
//! the stage's manifest records (shadow maps, BRDF table, media volume), and private sections
//! (kinds the format does not know, e.g. the BVH's leaf order), each under the format's XXH3-64
//! checksum; the manifest's content hash is the key. An entry that fails to open, fails a
//! checksum or carries another key is a miss with a warning, never an error.
//!
//! Writes are atomic (a temporary file in `DIR/tmp`, renamed into place), so concurrent compiles
//! sharing a directory see either no entry or a whole one; no lock is held. A hit sets the
//! entry's modification time to now, which `kiln cache gc` evicts by (least recently used first).

use std::borrow::Cow;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use kiln_format::manifest::Manifest;
use kiln_format::{Checksums, ContentHash, ContentHasher, FileWriter, KilnFile, SectionKind};

use crate::exit::{CliError, CliResult};

/// Version of the entry layout and key recipe; part of every key.
const LAYOUT_VERSION: &str = "kiln-cache-1";

/// Environment variable naming the cache directory when `--cache` is not given.
pub const ENV: &str = "KILN_CACHE";

/// Extension of entry files.
const EXT: &str = "kiln";

/// One section of an entry.
#[derive(Debug, Clone, PartialEq)]
pub struct EntrySection {
    /// Kind (a format kind, or a private one).
    pub kind: SectionKind,
    /// Index.
    pub index: u32,
    /// Bytes.
    pub bytes: Vec<u8>,
}

/// A stage's cached output.
#[derive(Debug, Clone, Default)]
pub struct Entry {
    /// The stage's manifest records (other fields default).
    pub manifest: Manifest,
    /// Sections, in the container's order.
    pub sections: Vec<EntrySection>,
}

impl Entry {
    /// Removes and returns the bytes of the section of `kind` and `index`.
    pub fn take(&mut self, kind: SectionKind, index: u32) -> Option<Vec<u8>> {
        let i = self.sections.iter().position(|s| s.kind == kind && s.index == index)?;
        Some(self.sections.remove(i).bytes)
    }
}

/// A stage key under construction: starts with the layout, compiler and algorithm versions and
/// the stage's name.
pub fn key(stage: &str) -> ContentHasher {
    let mut h = ContentHasher::new();
    h.part("layout", LAYOUT_VERSION.as_bytes())
        .part("compiler", env!("CARGO_PKG_VERSION").as_bytes())
        .part("algorithm", crate::bake::ALGORITHM_VERSION.as_bytes())
        .part("stage", stage.as_bytes());
    h
}

/// An open cache directory.
#[derive(Debug, Clone)]
pub struct Cache {
    dir: PathBuf,
}

/// Stage names are directory names: lower-case letters, digits and `-` only.
fn valid_stage(stage: &str) -> bool {
    !stage.is_empty() && stage.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
}

impl Cache {
    /// The directory from `--cache` (if given), else from `KILN_CACHE` (if set and not empty);
    /// `None` means no cache (the default: no state outside the output).
    pub fn dir_from(flag: Option<&Path>) -> Option<PathBuf> {
        flag.map(Path::to_path_buf)
            .or_else(|| std::env::var_os(ENV).filter(|v| !v.is_empty()).map(PathBuf::from))
    }

    /// Opens (creating if needed) the cache at `dir` and checks that it is writable. The error
    /// (exit 4) says which directory and what to do.
    pub fn open(dir: &Path) -> CliResult<Cache> {
        let fail = |what: &str, e: std::io::Error| {
            CliError::io(format!(
                "cache directory {}: {what}: {e} (make it writable, or choose another with --cache DIR or {ENV}, or drop --cache)",
                dir.display()
            ))
        };
        if dir.exists() && !dir.is_dir() {
            return Err(CliError::io(format!(
                "cache directory {}: exists and is not a directory (choose another with --cache DIR or {ENV})",
                dir.display()
            )));
        }
        std::fs::create_dir_all(dir.join("tmp")).map_err(|e| fail("cannot create it", e))?;
        // A probe file proves that entries can be written (a directory may exist read-only).
        tempfile::Builder::new()
            .prefix(".probe")
            .tempfile_in(dir.join("tmp"))
            .map_err(|e| fail("cannot write to it", e))?;
        let tag = dir.join("CACHEDIR.TAG");
        if !tag.exists() {
            let _ = std::fs::write(
                &tag,
                "Signature: 8a477f597d28d172789f06886806bc55\n# This is a kiln stage cache (kiln compile --cache); see kiln's docs/compiler.md, \"Stage cache\".\n",
            );
        }
        Ok(Cache { dir: dir.to_path_buf() })
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Path of the entry of `stage` under `key`.
    pub fn path(&self, stage: &str, key: &ContentHash) -> PathBuf {
        self.dir.join(stage).join(format!("{}.{EXT}", key.to_hex()))
    }

    /// The entry of `stage` under `key`: `Ok(None)` when there is none, `Err(why)` when one
    /// exists but is unreadable, damaged or not this key's (the caller warns and re-bakes).
    pub fn load(&self, stage: &str, key: &ContentHash) -> Result<Option<Entry>, String> {
        let path = self.path(stage, key);
        // Read, not memory-mapped: an entry truncated in place by another program while mapped
        // would be a SIGBUS; read bytes are only ever a short or damaged entry, which the layout
        // and checksum checks turn into a miss.
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            // None, or evicted by a concurrent `kiln cache gc`.
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(format!("{}: {e}", path.display())),
        };
        let file =
            KilnFile::from_bytes(&bytes, Checksums::Eager).map_err(|e| format!("{}: {e}", path.display()))?;
        drop(bytes);
        let manifest = file.manifest().map_err(|e| format!("{}: {e}", path.display()))?;
        let mut entry = Entry { manifest, sections: Vec::new() };
        for s in file.sections() {
            if s.entry.kind == kiln_format::sections::MANIFEST {
                if s.entry.content_hash != *key {
                    return Err(format!("{}: holds the entry of another key", path.display()));
                }
                continue;
            }
            let bytes = file.section_bytes(s).map_err(|e| format!("{}: {e}", path.display()))?;
            entry.sections.push(EntrySection {
                kind: s.entry.kind,
                index: s.entry.index,
                bytes: bytes.into_owned(),
            });
        }
        // Least recently used is least recently read or written: a hit renews the entry.
        if let Ok(f) = std::fs::File::options().append(true).open(&path) {
            let _ = f.set_modified(SystemTime::now());
        }
        Ok(Some(entry))
    }

    /// Stores an entry of `stage` under `key`: written to a temporary file in `DIR/tmp` and
    /// renamed into place, so that readers never see a partial entry. Returns why it failed (the
    /// caller warns; the compile goes on).
    pub fn store(
        &self,
        stage: &str,
        key: &ContentHash,
        manifest: &Manifest,
        sections: &[(SectionKind, u32, &[u8])],
    ) -> Result<(), String> {
        debug_assert!(valid_stage(stage));
        let path = self.path(stage, key);
        let run = || -> Result<(), String> {
            let mut w = FileWriter::new();
            w.manifest(manifest, *key).map_err(|e| e.to_string())?;
            for &(kind, index, bytes) in sections {
                let version = kiln_format::sections::info(kind).map_or(1, |k| k.version);
                w.raw(kind, index, version, Cow::Borrowed(bytes), *key).map_err(|e| e.to_string())?;
            }
            let io = |e: std::io::Error| e.to_string();
            std::fs::create_dir_all(self.dir.join(stage)).map_err(io)?;
            let tmp = tempfile::Builder::new()
                .prefix(&format!("{stage}-"))
                .suffix(".tmp")
                .tempfile_in(self.dir.join("tmp"))
                .map_err(io)?;
            let mut buf = std::io::BufWriter::with_capacity(1 << 20, tmp);
            w.write_to(&mut buf).map_err(|e| e.to_string())?;
            buf.flush().map_err(io)?;
            let tmp = buf.into_inner().map_err(|e| e.to_string())?;
            // No fsync: an entry cut short by a crash fails its checksums and is re-baked.
            tmp.persist(&path).map_err(|e| e.error.to_string())?;
            Ok(())
        };
        run().map_err(|e| format!("cannot store {}: {e}", path.display()))
    }
}

/// One entry found by [`scan`].
#[derive(Debug, Clone)]
pub struct Found {
    /// Stage (its directory).
    pub stage: String,
    /// Path.
    pub path: PathBuf,
    /// Size in bytes.
    pub bytes: u64,
    /// Last use (modification time).
    pub used: SystemTime,
}

/// Every entry under `dir` (stage directories only; `tmp` and other files are not entries).
pub fn scan(dir: &Path) -> CliResult<Vec<Found>> {
    let err = |p: &Path, e: std::io::Error| CliError::io(format!("{}: {e}", p.display()));
    if !dir.is_dir() {
        return Err(CliError::io(format!("cache directory {}: not found", dir.display())));
    }
    let mut found = Vec::new();
    for stage in std::fs::read_dir(dir).map_err(|e| err(dir, e))? {
        let stage = stage.map_err(|e| err(dir, e))?;
        let name = stage.file_name().to_string_lossy().into_owned();
        if name == "tmp" || !valid_stage(&name) || !stage.path().is_dir() {
            continue;
        }
        for entry in std::fs::read_dir(stage.path()).map_err(|e| err(&stage.path(), e))? {
            let entry = entry.map_err(|e| err(&stage.path(), e))?;
            let path = entry.path();
            if path.extension().and_then(|e| e.to_str()) != Some(EXT) {
                continue;
            }
            // Removed by a concurrent gc since the listing: not an entry any more.
            let Ok(meta) = entry.metadata() else { continue };
            found.push(Found {
                stage: name.clone(),
                path,
                bytes: meta.len(),
                used: meta.modified().unwrap_or(SystemTime::UNIX_EPOCH),
            });
        }
    }
    found.sort_by(|a, b| (a.used, &a.path).cmp(&(b.used, &b.path)));
    Ok(found)
}

/// Per-stage figures of a cache.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Stats {
    /// The directory.
    pub dir: String,
    /// Entries.
    pub entries: u64,
    /// Bytes of all entries.
    pub bytes: u64,
    /// Per stage: (stage, entries, bytes), by name.
    pub stages: Vec<StageStats>,
}

/// One stage's figures.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct StageStats {
    /// Stage.
    pub stage: String,
    /// Entries.
    pub entries: u64,
    /// Bytes.
    pub bytes: u64,
}

/// Figures of the cache at `dir`.
pub fn stats(dir: &Path) -> CliResult<Stats> {
    let found = scan(dir)?;
    let mut s = Stats { dir: dir.display().to_string(), ..Default::default() };
    for f in &found {
        s.entries += 1;
        s.bytes += f.bytes;
        match s.stages.iter_mut().find(|x| x.stage == f.stage) {
            Some(x) => {
                x.entries += 1;
                x.bytes += f.bytes;
            }
            None => s.stages.push(StageStats { stage: f.stage.clone(), entries: 1, bytes: f.bytes }),
        }
    }
    s.stages.sort_by(|a, b| a.stage.cmp(&b.stage));
    Ok(s)
}

/// What `gc` did.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Collected {
    /// Entries removed.
    pub removed: u64,
    /// Bytes removed.
    pub removed_bytes: u64,
    /// Entries kept.
    pub kept: u64,
    /// Bytes kept.
    pub kept_bytes: u64,
}

/// Removes least recently used entries until the rest take at most `max_bytes`; also removes
/// temporary files older than a day (left by a compile that was killed).
pub fn gc(dir: &Path, max_bytes: u64) -> CliResult<Collected> {
    let found = scan(dir)?;
    let mut total: u64 = found.iter().map(|f| f.bytes).sum();
    let mut c = Collected::default();
    for f in found {
        if total <= max_bytes {
            c.kept += 1;
            c.kept_bytes += f.bytes;
            continue;
        }
        match std::fs::remove_file(&f.path) {
            Ok(()) => {}
            // Already gone (another gc): it no longer counts either way.
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(CliError::io(format!("cannot remove {}: {e}", f.path.display()))),
        }
        total -= f.bytes;
        c.removed += 1;
        c.removed_bytes += f.bytes;
    }
    if let Ok(tmp) = std::fs::read_dir(dir.join("tmp")) {
        let day = std::time::Duration::from_secs(24 * 3600);
        for t in tmp.flatten() {
            let old = t
                .metadata()
                .and_then(|m| m.modified())
                .is_ok_and(|m| SystemTime::now().duration_since(m).is_ok_and(|age| age > day));
            if old {
                let _ = std::fs::remove_file(t.path());
            }
        }
    }
    Ok(c)
}

/// Parses a size: a number of bytes, optionally with a binary unit K, M, G or T (also written
/// KB, KiB, ...; 1K = 1024).
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let digits = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (num, unit) = t.split_at(digits);
    let value: f64 = num.parse().map_err(|_| format!("{s:?} is not a size (e.g. 500M, 2G, 1048576)"))?;
    let unit = unit.trim().to_ascii_lowercase();
    let shift = match unit.trim_end_matches("ib").trim_end_matches('b') {
        "" => 0,
        "k" => 10,
        "m" => 20,
        "g" => 30,
        "t" => 40,
        _ => return Err(format!("{s:?}: unknown unit {unit:?} (use K, M, G or T)")),
    };
    let bytes = value * (1u64 << shift) as f64;
    if !bytes.is_finite() || bytes < 0.0 || bytes > u64::MAX as f64 {
        return Err(format!("{s:?} is out of range"));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("1048576"), Ok(1 << 20));
        assert_eq!(parse_size("500M"), Ok(500 << 20));
        assert_eq!(parse_size("2GiB"), Ok(2 << 30));
        assert_eq!(parse_size("1.5k"), Ok(1536));
        assert_eq!(parse_size("3 KB"), Ok(3072));
        assert!(parse_size("12X").is_err());
        assert!(parse_size("M").is_err());
    }
}
