//! Files an asset refers to (buffers, images, MTL libraries) and the main input, read within
//! bounds: a regular file (a device such as `/dev/zero`, a FIFO or a folder would be read until
//! memory runs out, or block forever), at most `--max-file-size` bytes, and images at most
//! `--max-image-side` pixels on a side, checked from the header before decoding (a 141 KB PNG can
//! declare 12,000 × 12,000 pixels: 2.7 GiB decoded).
//!
//! Files an asset names (not those named on the command line) are also **confined**: they must
//! lie under the main input's folder, the sidecar's, or a `--search-path` folder, so that a
//! service compiling uploaded assets does not read `../../etc/passwd` for them
//! (`--allow-any-path` lifts it).
//!
//! The limits and the confinement are process-wide: the command line sets them once before
//! importing ([`set_limits`], [`confine`]), and the importers and the parallel image decoder read
//! them. A library caller that sets no confinement reads any path.

use std::io::Read;
use std::path::{Component, Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

/// The default largest file an import reads: 4 GiB.
pub const DEFAULT_MAX_FILE_BYTES: u64 = 4 << 30;
/// The default largest image side: 4096 pixels. What one image costs grows with its texels: on
/// two cores a 4096² texture compiles (decode, mip chain, BC7, its error measured) in 10 s and
/// 0.5 GB, an 8192² one in 37 s and 1.9 GB (past a 2 GiB process), and a 141 KB PNG can declare
/// either. Larger images need `--max-image-side`.
pub const DEFAULT_MAX_IMAGE_SIDE: u32 = 4096;

static MAX_FILE_BYTES: AtomicU64 = AtomicU64::new(DEFAULT_MAX_FILE_BYTES);
static MAX_IMAGE_SIDE: AtomicU32 = AtomicU32::new(DEFAULT_MAX_IMAGE_SIDE);

/// Sets the largest file and image side the imports accept.
pub fn set_limits(max_file_bytes: u64, max_image_side: u32) {
    MAX_FILE_BYTES.store(max_file_bytes, Ordering::Relaxed);
    MAX_IMAGE_SIDE.store(max_image_side, Ordering::Relaxed);
}

/// The largest image side the imports accept.
pub fn max_image_side() -> u32 {
    MAX_IMAGE_SIDE.load(Ordering::Relaxed)
}

/// Where referenced files may lie: folders (canonical) and single files named on the command line.
#[derive(Debug, Clone)]
struct Confinement {
    roots: Vec<PathBuf>,
    files: Vec<PathBuf>,
}

static CONFINEMENT: Mutex<Option<Confinement>> = Mutex::new(None);

/// Confines the files an asset refers to: each must lie under one of `roots` (folders) or be one
/// of `files` (named on the command line). `None` lifts the rule (`--allow-any-path`).
pub fn confine(rule: Option<(&[PathBuf], &[PathBuf])>) {
    // Each as written and with links resolved: a path is judged in both forms below.
    let both = |paths: &[PathBuf]| paths.iter().flat_map(|p| [lexical(p), resolved(p)]).collect();
    let rule = rule.map(|(roots, files)| Confinement { roots: both(roots), files: both(files) });
    *CONFINEMENT.lock().unwrap_or_else(|e| e.into_inner()) = rule;
}

/// `path` made absolute against the working folder, with `.` and `..` resolved as written (links
/// not followed).
pub(crate) fn lexical(path: &Path) -> PathBuf {
    let mut out =
        if path.is_absolute() { PathBuf::new() } else { std::env::current_dir().unwrap_or_default() };
    for c in path.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other.as_os_str()),
        }
    }
    out
}

/// `path` with links resolved where it exists (a link inside a root may lead out of it), else
/// [`lexical`].
fn resolved(path: &Path) -> PathBuf {
    path.canonicalize().unwrap_or_else(|_| lexical(path))
}

/// Whether the asset `what` (e.g. "texture 'wood.png'") may read `path` under the confinement;
/// the error names the reference, the file and the rule, and how to lift it.
pub fn check_confined(what: &str, path: &Path) -> Result<(), String> {
    let guard = CONFINEMENT.lock().unwrap_or_else(|e| e.into_inner());
    let Some(rule) = guard.as_ref() else { return Ok(()) };
    let inside = |p: &Path| rule.files.iter().any(|f| f == p) || rule.roots.iter().any(|r| p.starts_with(r));
    // Inside both as written and with links resolved. A file outside that does not exist is
    // refused as outside, not reported missing: the error must not tell what exists there.
    if inside(&lexical(path)) && inside(&resolved(path)) {
        return Ok(());
    }
    let mut roots: Vec<String> = rule.roots.iter().map(|r| r.display().to_string()).collect();
    roots.dedup();
    Err(format!(
        "{what} refers to {}, outside the folders an asset may read from ({}): move the file there, \
         add its folder with --search-path DIR, or pass --allow-any-path",
        path.display(),
        if roots.is_empty() { "none".into() } else { roots.join(", ") }
    ))
}

/// Why a file an asset names was not read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReadError {
    /// Outside the confinement: the compile fails (an asset reaching out of its folder is not a
    /// missing texture to warn about).
    Confined(String),
    /// Missing, not a regular file, or too large.
    Unreadable(String),
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::Confined(m) | ReadError::Unreadable(m) => f.write_str(m),
        }
    }
}

/// [`check_confined`], then [`read_bounded`]: how files an asset names are read.
pub fn read_referenced(what: &str, path: &Path) -> Result<Vec<u8>, ReadError> {
    check_confined(what, path).map_err(ReadError::Confined)?;
    read_bounded(path).map_err(ReadError::Unreadable)
}

/// Reads `path` whole if it is a regular file of at most the size limit; the error says which
/// rule it broke and how to lift the size limit.
pub fn read_bounded(path: &Path) -> Result<Vec<u8>, String> {
    // Metadata first: opening a FIFO blocks until a writer comes.
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a folder, not a regular file"
        } else {
            "not a regular file (a device, FIFO or socket)"
        };
        return Err(format!("{} is {what}: an asset may refer only to regular files", path.display()));
    }
    let limit = MAX_FILE_BYTES.load(Ordering::Relaxed);
    let too_large = |size: u64| {
        format!(
            "{} is {size} bytes, more than the {limit}-byte limit: raise it with --max-file-size",
            path.display()
        )
    };
    if meta.len() > limit {
        return Err(too_large(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    // The file may grow between the check and the read: read one byte past the limit at most.
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// `rel` under `base` with each component that does not exist as written matched to the one
/// entry of its folder whose name differs only in case (an asset made on a file system that does
/// not tell case apart, e.g. Sponza's `00_SKAP.JPG` for `00_skap.JPG`); `None` when a component
/// matches nothing, or several entries. Backslashes in `rel` are folder separators.
pub fn resolve_case_insensitive(base: &Path, rel: &str) -> Option<PathBuf> {
    let rel = rel.replace('\\', "/");
    // An input in the working folder has an empty parent.
    let mut at = if base.as_os_str().is_empty() { PathBuf::from(".") } else { base.to_path_buf() };
    for c in Path::new(&rel).components() {
        let Component::Normal(name) = c else {
            at.push(c.as_os_str());
            continue;
        };
        let exact = at.join(name);
        if exact.exists() {
            at = exact;
            continue;
        }
        let want = name.to_str()?.to_lowercase();
        let mut found = std::fs::read_dir(&at)
            .ok()?
            .filter_map(Result::ok)
            .filter(|e| e.file_name().to_str().is_some_and(|n| n.to_lowercase() == want));
        let first = found.next()?;
        if found.next().is_some() {
            return None;
        }
        at = first.path();
    }
    Some(at)
}

/// Decodes an image whose dimensions, read from its header first, are within the image limit;
/// the decoder's allocations are bounded by the same limit.
pub fn decode_image(bytes: &[u8]) -> Result<image::DynamicImage, String> {
    let reader = || image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format();
    let (w, h) =
        reader().map_err(|e| e.to_string())?.into_dimensions().map_err(|e| format!("cannot decode: {e}"))?;
    let side = max_image_side();
    if w > side || h > side {
        return Err(format!(
            "{w} x {h} pixels, more than {side} on a side: not decoded (raise --max-image-side to read it)"
        ));
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(side);
    limits.max_image_height = Some(side);
    // RGBA in 32-bit floats at most, twice (the decoder's buffer and the conversion), and never
    // over 1 GiB: the decoder refuses beyond it rather than the process aborting.
    limits.max_alloc = Some((2 * 16 * u64::from(w) * u64::from(h) + (64 << 20)).min(1 << 30));
    let mut r = reader().map_err(|e| e.to_string())?;
    r.limits(limits);
    r.decode().map_err(|e| format!("cannot decode: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_within_the_limit_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("b.bin");
        std::fs::write(&file, [7u8; 100]).unwrap();
        assert_eq!(read_bounded(&file).unwrap().len(), 100);
        let e = read_bounded(dir.path()).unwrap_err();
        assert!(e.contains("a folder"), "{e}");
        #[cfg(unix)]
        {
            let e = read_bounded(Path::new("/dev/zero")).unwrap_err();
            assert!(e.contains("not a regular file"), "{e}");
        }
        // The limit (other tests in this binary read small files only).
        set_limits(99, DEFAULT_MAX_IMAGE_SIDE);
        let e = read_bounded(&file).unwrap_err();
        set_limits(DEFAULT_MAX_FILE_BYTES, DEFAULT_MAX_IMAGE_SIDE);
        assert!(e.contains("--max-file-size") && e.contains("100 bytes"), "{e}");
    }

    #[test]
    fn an_image_declaring_more_pixels_than_the_limit_is_not_decoded() {
        // A valid PNG header and IHDR declaring 20000 x 3 pixels, with no image data: the
        // header alone must refuse it.
        let mut png = Vec::new();
        image::codecs::png::PngEncoder::new(&mut png)
            .write_image(&[0u8; 4 * 4], 4, 1, image::ExtendedColorType::Rgba8)
            .unwrap();
        decode_image(&png).unwrap();
        // IHDR's width sits at bytes 16..20; its CRC after the 13 data bytes would now be wrong,
        // so recompute it.
        png[16..20].copy_from_slice(&20000u32.to_be_bytes());
        let crc = crc32(&png[12..29]);
        png[29..33].copy_from_slice(&crc.to_be_bytes());
        let e = decode_image(&png).unwrap_err();
        assert!(e.contains("20000 x 1") && e.contains("--max-image-side"), "{e}");
    }

    /// CRC-32 (ISO-HDLC), bit by bit: the PNG chunk checksum, written here independently.
    fn crc32(data: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in data {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 { 0xedb8_8320 ^ (c >> 1) } else { c >> 1 };
            }
        }
        !c
    }

    use image::ImageEncoder;
}
