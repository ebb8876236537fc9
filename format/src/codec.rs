//! Section codecs: compressing a section for the writer, decoding it for the reader.
//!
//! Codec 1 is zstd (RFC 8878): a section is stored as exactly one zstd frame whose header
//! declares the decoded size, which must equal the table's `raw_size`. The reader checks that size
//! against its limit before allocating, decodes into a buffer of exactly that size (the decoder
//! cannot write past it, whatever the frame claims) and refuses a frame that is truncated, is
//! followed by other bytes, or decodes to a different length.

use crate::error::{ErrorKind, FormatError, Result};

/// The zstd level writers use. Pinned: together with the parameters in [`compress_zstd`] and the
/// zstd library version (locked in `Cargo.lock`), it makes the stored bytes a function of the
/// section's bytes only. Chosen by measurement on pica_pica's 387 MB of sections
/// (`examples/codec_levels.rs`, docs/testing.md): level 9 stores 75.8 MB in 14 s of one core,
/// level 3 80.6 MB in 2.6 s, level 19 59.5 MB in 208 s; decoding takes about 1 s at every level.
pub const ZSTD_LEVEL: i32 = 9;

/// The largest decoded section a reader accepts unless told otherwise: 4 GiB. A larger declared
/// `raw_size` is refused while the layout is validated, before anything is allocated.
pub const DEFAULT_MAX_DECODED: u64 = 1 << 32;

/// The zstd frame magic number, little-endian (RFC 8878 §3.1.1).
const ZSTD_MAGIC: [u8; 4] = [0x28, 0xB5, 0x2F, 0xFD];

/// 64-byte aligned owned bytes, so that sections held in memory (a copied file, a decoded
/// section) keep the alignment a memory map gives for free and can be viewed as any POD type.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Block([u8; 64]);

/// Owned, 64-byte aligned bytes.
pub(crate) struct Aligned {
    blocks: Vec<Block>,
    len: usize,
}

impl Aligned {
    /// `len` zero bytes; `None` when the allocation fails (instead of aborting the process).
    pub(crate) fn zeroed(len: usize) -> Option<Aligned> {
        let n = len.div_ceil(64);
        let mut blocks = Vec::new();
        blocks.try_reserve_exact(n).ok()?;
        blocks.resize(n, Block([0; 64]));
        Some(Aligned { blocks, len })
    }

    /// A copy of `bytes`.
    pub(crate) fn copy_of(bytes: &[u8]) -> Aligned {
        let mut blocks = vec![Block([0; 64]); bytes.len().div_ceil(64)];
        for (block, chunk) in blocks.iter_mut().zip(bytes.chunks(64)) {
            block.0[..chunk.len()].copy_from_slice(chunk);
        }
        Aligned { blocks, len: bytes.len() }
    }

    pub(crate) fn bytes(&self) -> &[u8] {
        // SAFETY: `Block` is 64 plain bytes with no padding, so a slice of blocks is a slice of
        // `64 * blocks.len()` initialised bytes; `len` never exceeds that.
        let all =
            unsafe { std::slice::from_raw_parts(self.blocks.as_ptr().cast::<u8>(), self.blocks.len() * 64) };
        &all[..self.len]
    }

    fn bytes_mut(&mut self) -> &mut [u8] {
        // SAFETY: as in `bytes`; the blocks are exclusively borrowed.
        let all = unsafe {
            std::slice::from_raw_parts_mut(self.blocks.as_mut_ptr().cast::<u8>(), self.blocks.len() * 64)
        };
        &mut all[..self.len]
    }
}

/// Compresses `bytes` as one zstd frame: level [`ZSTD_LEVEL`], the decoded size in the frame
/// header, zstd's own content checksum (XXH64 of the decoded bytes, which the decoder verifies:
/// a second check on the decoded content beside the table's checksum of the stored bytes), no
/// dictionary id; on `workers` threads (at least one).
///
/// Always zstd's multithreaded compressor: it cuts a large section into jobs of a size set by
/// the level and compresses them in parallel, and its frames are the same for any number of
/// workers from one up (unlike the single-threaded compressor's, which differ from them), so
/// the bytes depend on the section's bytes only, not on the machine
/// (`tests/codec.rs::frames_do_not_depend_on_the_worker_count`). Sections of at most 512 KiB
/// zstd compresses on the calling thread whatever the count.
pub fn compress_zstd(bytes: &[u8], workers: u32) -> std::io::Result<Vec<u8>> {
    use zstd::zstd_safe::CParameter;
    let mut c = zstd::bulk::Compressor::new(ZSTD_LEVEL)?;
    c.set_parameter(CParameter::ContentSizeFlag(true))?;
    c.set_parameter(CParameter::ChecksumFlag(true))?;
    c.set_parameter(CParameter::DictIdFlag(false))?;
    c.set_parameter(CParameter::NbWorkers(workers.max(1)))?;
    c.compress(bytes)
}

/// Decodes a zstd-coded section of `raw_size` bytes from its stored bytes; `max` is the reader's
/// limit on `raw_size`. Nothing sized by the frame or the table is allocated before `raw_size`
/// has been checked against `max`, and the frame is checked against `raw_size` before decoding.
pub(crate) fn decode_zstd(stored: &[u8], raw_size: u64, max: u64) -> Result<Aligned> {
    let bad = |msg: String| FormatError::new(ErrorKind::Decode(msg));
    if raw_size > max {
        return Err(FormatError::new(ErrorKind::DecodedTooLarge { declared: raw_size, limit: max }));
    }
    if stored.get(..4) != Some(&ZSTD_MAGIC[..]) {
        return Err(bad(format!(
            "the {}-byte section does not start with a zstd frame (magic 28 B5 2F FD)",
            stored.len()
        )));
    }
    // One frame exactly: a shorter stored length than the frame needs is truncation, a longer
    // one trailing bytes (the one-shot decoder would go on to decode further frames).
    match zstd::zstd_safe::find_frame_compressed_size(stored) {
        Ok(n) if n == stored.len() => {}
        Ok(n) => {
            return Err(bad(format!(
                "{} bytes follow the zstd frame's {n} (one frame per section)",
                stored.len() - n
            )));
        }
        Err(_) => {
            return Err(bad(format!("the zstd frame is truncated or malformed ({} bytes)", stored.len())));
        }
    }
    match zstd::zstd_safe::get_frame_content_size(stored) {
        Ok(Some(n)) if n == raw_size => {}
        Ok(Some(n)) => {
            return Err(bad(format!("the zstd frame declares {n} decoded bytes, the table {raw_size}")));
        }
        Ok(None) => return Err(bad("the zstd frame does not declare its decoded size".into())),
        Err(_) => return Err(bad("the zstd frame header is malformed".into())),
    }
    let len = usize::try_from(raw_size).map_err(|_| bad(format!("{raw_size} bytes do not fit in memory")))?;
    let mut out = Aligned::zeroed(len)
        .ok_or_else(|| bad(format!("cannot allocate {raw_size} bytes for the decoded section")))?;
    let mut dctx =
        zstd::zstd_safe::DCtx::try_create().ok_or_else(|| bad("cannot create a zstd decoder".into()))?;
    // The output is a slice of exactly raw_size bytes: the decoder fails rather than write more.
    let written = dctx
        .decompress(out.bytes_mut(), stored)
        .map_err(|code| bad(format!("zstd: {}", zstd::zstd_safe::get_error_name(code))))?;
    if written != len {
        return Err(bad(format!("the zstd frame decoded to {written} bytes, the table declares {raw_size}")));
    }
    Ok(out)
}
