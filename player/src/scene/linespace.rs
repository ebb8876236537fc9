//! The voxel grid and line space on the GPU: the arrays the chosen techniques read, and only
//! those, concatenated into one space of 32-bit words that is split into storage buffers
//! ("chunks") no larger than the device allows. The queries (`shaders/common/linespace.glsl`)
//! find an array's word `i` at `base + i`, in chunk `(base + i) >> chunk_shift`.
//!
//! Why one space and not a buffer per array: PNMT alone is 301 MiB on `pica_pica`, over
//! lavapipe's 128 MiB `maxStorageBufferRange`, and which array outgrows the limit depends on the
//! scene and the variants; one chunked space splits whatever is large with one mechanism, and
//! binds a fixed number of buffers (`MAX_CHUNKS`) whatever the file holds.

use kiln_format::gpu::GpuGrid;
use kiln_format::linespace::glsl::{MAX_CHUNKS, NO_BASE};
use kiln_format::linespace::{LineSpace, SECTIONS, Variants};
use kiln_format::read::KilnFile;
use kiln_format::table::SectionKind;

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Buffer, Gpu, vk};
use crate::scene::upload::Uploader;

/// The arrays a technique reads, as bits of [`crate::render::Needs::line_space`].
#[derive(Debug)]
pub struct LsArrays;

impl LsArrays {
    /// Cell triangle lists (`VOXO`, `VOXT`): exact triangle tests in a cell.
    pub const CELL_LISTS: u32 = 1 << 0;
    /// Slots and shaft bits (`LSLT`, `LSBN`): the binary line space.
    pub const SHAFTS: u32 = 1 << 1;
    /// Ranks (`LSRK`): what every per-shaft record is found by.
    pub const RANKS: u32 = 1 << 2;
    /// Candidate lists (`LSCO`, `LSCE`).
    pub const CANDIDATES: u32 = 1 << 3;
    /// PNMT records (`LSPN`).
    pub const PNMT: u32 = 1 << 4;
    /// Pre-illuminated records (`LSPI`).
    pub const PREILLUM: u32 = 1 << 5;
    /// Every array.
    pub const ALL: u32 = (1 << 6) - 1;
    /// With this bit, arrays the file lacks are left out instead of refused (ray benchmarks
    /// measure whatever variants the file has).
    pub const IF_PRESENT: u32 = 1 << 31;
    /// With this bit, the ranks and candidate lists too if the file has them (exact tests of a
    /// shaft's triangles instead of its cell's).
    pub const CANDIDATES_IF_PRESENT: u32 = 1 << 30;

    /// What a closest-hit query through the candidate lists reads.
    pub const CANDIDATE_QUERY: u32 = Self::CELL_LISTS | Self::SHAFTS | Self::RANKS | Self::CANDIDATES;
    /// What a PNMT query reads.
    pub const PNMT_QUERY: u32 = Self::SHAFTS | Self::RANKS | Self::PNMT;
    /// What a binary shadow query with exact end cells reads.
    pub const BINARY_QUERY: u32 = Self::CELL_LISTS | Self::SHAFTS;
}

/// The bit that asks for each of `kiln_format::linespace::SECTIONS` (the [`GpuGrid`] base order).
const ARRAY_BITS: [u32; 9] = [
    LsArrays::CELL_LISTS,
    LsArrays::CELL_LISTS,
    LsArrays::SHAFTS,
    LsArrays::SHAFTS,
    LsArrays::RANKS,
    LsArrays::CANDIDATES,
    LsArrays::CANDIDATES,
    LsArrays::PNMT,
    LsArrays::PREILLUM,
];

/// The variant that holds the arrays of `bit` (the voxel grid's cell lists come with any).
fn variant_of(bit: u32) -> u32 {
    match bit {
        LsArrays::CANDIDATES => Variants::CANDIDATES,
        LsArrays::PNMT => Variants::PNMT,
        LsArrays::PREILLUM => Variants::PREILLUM,
        _ => Variants::BINARY,
    }
}

/// The variants that hold the arrays `bits` asks for.
fn variants_of(bits: u32) -> u32 {
    (0..6).map(|i| 1u32 << i).filter(|b| bits & b != 0).fold(0, |v, b| v | variant_of(b))
}

/// The `--shaft-variants` a file must hold for the arrays `wanted` asks for (0 for none): the
/// binary variant indexes every other.
pub fn variants_needed(wanted: u32) -> u32 {
    if wanted & LsArrays::ALL == 0 { 0 } else { Variants::BINARY | variants_of(wanted) }
}

/// Where each needed array goes in the word space, decided on the CPU before the device exists.
#[derive(Debug, Clone)]
pub struct LineSpaceLayout {
    /// The header as the shaders read it (`chunk_shift` set at upload).
    pub grid: GpuGrid,
    /// Base word of each of `SECTIONS` (or [`NO_BASE`]).
    bases: [u32; 9],
    /// Words in the space.
    pub words: u64,
}

impl LineSpaceLayout {
    /// Validates the file's grid and lays out the arrays `wanted` asks for; errors name the
    /// variants the file lacks and the compile flag that adds them. `None` when `wanted` has
    /// [`LsArrays::IF_PRESENT`] and the file has no grid.
    pub fn new(
        file: &KilnFile,
        triangles: usize,
        materials: usize,
        wanted: u32,
    ) -> PlayResult<Option<LineSpaceLayout>> {
        let bad = |e: kiln_format::error::FormatError| {
            PlayError::new(Exit::BadInput, format!("invalid .kiln file: {e}"))
        };
        let optional = wanted & LsArrays::IF_PRESENT != 0;
        let ls = LineSpace::new(file, triangles, materials).map_err(bad)?;
        let Some(ls) = ls else {
            if optional {
                return Ok(None);
            }
            return Err(missing("the file has no voxel grid or line space", wanted));
        };
        let h = ls.header;
        let present = |bit: u32| bit == LsArrays::CELL_LISTS || h.variants & variant_of(bit) != 0;
        let mut wanted = wanted;
        if wanted & LsArrays::CANDIDATES_IF_PRESENT != 0 && h.variants & Variants::CANDIDATES != 0 {
            wanted |= LsArrays::RANKS | LsArrays::CANDIDATES;
        }
        let lacking: u32 = (0..6).map(|i| 1u32 << i).filter(|&b| wanted & b != 0 && !present(b)).sum();
        if lacking != 0 && !optional {
            let what = format!("the file's line space lacks {}", Variants::list(variants_of(lacking)));
            return Err(missing(&what, wanted));
        }
        let mut bases = [NO_BASE; 9];
        let mut words = 0u64;
        for (i, (kind, &bit)) in SECTIONS.iter().zip(&ARRAY_BITS).enumerate() {
            if wanted & bit == 0 || !present(bit) {
                continue;
            }
            let n = file.find(*kind, 0).map_or(0, |s| s.entry.raw_size / 4);
            // Aligned to 4 words: a full 16-byte record never straddles two chunks (compact ones
            // may: every word is read on its own, through its chunk).
            words = words.next_multiple_of(4);
            bases[i] = u32::try_from(words).map_err(|_| too_large(words))?;
            words += n;
        }
        if words >= u32::MAX as u64 {
            return Err(too_large(words));
        }
        let grid = GpuGrid {
            origin: h.origin.map(|v| v as f32),
            cell: h.cell as f32,
            origin_lo: h.origin.map(|v| (v - v as f32 as f64) as f32),
            inv_cell: (1.0 / h.cell) as f32,
            dims: h.dims,
            shaft_res: h.shaft_res,
            margin: h.margin as f32,
            words_per_slot: ls.words_per_slot as u32,
            variants: h.variants,
            // The early exit compares single-precision keys in [0, 2]: a few ulps of slack more.
            key_eps: (h.key_eps() + 1e-5) as f32,
            pnmt_step: h.pnmt_step() as f32,
            chunk_shift: 0,
            pnmt_layout: h.pnmt_layout,
            reserved: 0,
            bases_a: [bases[0], bases[1], bases[2], bases[3]],
            bases_b: [bases[4], bases[5], bases[6], bases[7]],
            bases_c: [bases[8], 0, 0, 0],
        };
        Ok(Some(LineSpaceLayout { grid, bases, words }))
    }

    /// Base word of `kind`'s array, if it is uploaded.
    fn base_of(&self, kind: SectionKind) -> Option<u64> {
        let i = SECTIONS.iter().position(|k| *k == kind)?;
        (self.bases[i] != NO_BASE).then_some(self.bases[i] as u64)
    }

    /// Whether a section of `kind` is one of the uploaded arrays.
    pub fn uploads(&self, kind: SectionKind) -> bool {
        self.base_of(kind).is_some()
    }

    /// Whether a section of `kind` is one of the arrays that `wanted` ([`LsArrays`] bits) asks
    /// for, known before the layout is read.
    pub fn may_upload(kind: SectionKind, wanted: u32) -> bool {
        SECTIONS.iter().zip(ARRAY_BITS).any(|(k, bit)| *k == kind && wanted & bit != 0)
    }
}

fn missing(what: &str, wanted: u32) -> PlayError {
    PlayError::new(
        Exit::Usage,
        format!(
            "{what}, which the chosen technique reads: recompile the scene with \
             `kiln compile --shaft-variants {}` (or choose another technique)",
            Variants::list(variants_needed(wanted))
        ),
    )
}

fn too_large(words: u64) -> PlayError {
    PlayError::new(
        Exit::Gpu,
        format!(
            "the line space's arrays hold {} MiB, more than 16 GiB of queries can address: compile with a \
             lower --voxel-res or --shaft-res",
            words >> 18
        ),
    )
}

/// The line space resident on the GPU.
#[derive(Debug)]
pub struct LineSpaceBuffers {
    /// [`GpuGrid`] (uniform).
    pub grid: Buffer,
    /// The word space, in chunks of `1 << chunk_shift` words (the last one shorter).
    pub chunks: Vec<Buffer>,
    /// What `grid` holds.
    pub header: GpuGrid,
    layout: LineSpaceLayout,
}

impl LineSpaceBuffers {
    /// Allocates the chunks for `layout` within the device's storage-buffer limit and uploads
    /// the header; the arrays follow as their sections stream past ([`Self::upload`]).
    pub fn new(gpu: &Gpu, layout: &LineSpaceLayout, up: &mut Uploader) -> PlayResult<LineSpaceBuffers> {
        // The largest power of two of words within the limit, at most 2^29 (2 GiB).
        let limit_words = (gpu.max_storage_buffer() / 4).clamp(4, 1 << 29);
        let shift = 63 - limit_words.leading_zeros();
        let chunk_words = 1u64 << shift;
        let count = layout.words.div_ceil(chunk_words).max(1);
        if count > MAX_CHUNKS as u64 {
            return Err(PlayError::new(
                Exit::Gpu,
                format!(
                    "the line space's arrays hold {} MiB, more than {MAX_CHUNKS} storage buffers of {} MiB \
                     (this device's limit) can bind: compile with a lower --voxel-res or --shaft-res, or \
                     fewer --shaft-variants",
                    (layout.words * 4) >> 20,
                    (chunk_words * 4) >> 20
                ),
            ));
        }
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let mut made = LineSpaceBuffers {
            grid: Buffer::uploaded(
                gpu,
                "line-space grid",
                size_of::<GpuGrid>() as u64,
                vk::BufferUsageFlags::UNIFORM_BUFFER,
            )?,
            chunks: Vec::new(),
            header: GpuGrid { chunk_shift: shift, ..layout.grid },
            layout: layout.clone(),
        };
        for c in 0..count {
            let words = (layout.words - c * chunk_words).clamp(4, chunk_words);
            made.chunks.push(Buffer::uploaded(gpu, &format!("line-space chunk {c}"), words * 4, storage)?);
        }
        up.buffer(&made.grid, 0, bytemuck::bytes_of(&made.header))?;
        Ok(made)
    }

    /// Whether the section `kind` is one of the uploaded arrays.
    pub fn uploads(&self, kind: SectionKind) -> bool {
        self.layout.uploads(kind)
    }

    /// Uploads the section `kind` (its bytes), one of the arrays ([`Self::uploads`]), split at
    /// chunk boundaries.
    pub fn upload(&self, kind: SectionKind, bytes: &[u8], up: &mut Uploader) -> PlayResult {
        let Some(base) = self.layout.base_of(kind) else { return Ok(()) };
        let chunk_bytes = 4u64 << self.header.chunk_shift;
        let mut at = base * 4;
        let mut done = 0usize;
        while done < bytes.len() {
            let (chunk, offset) = ((at / chunk_bytes) as usize, at % chunk_bytes);
            let n = ((chunk_bytes - offset) as usize).min(bytes.len() - done);
            up.buffer(&self.chunks[chunk], offset, &bytes[done..done + n])?;
            done += n;
            at += n as u64;
        }
        Ok(())
    }

    /// The bindings [`Self::writes`] fills: the header, then [`MAX_CHUNKS`] storage buffers.
    pub fn bindings() -> Vec<crate::gpu::Binding> {
        use crate::gpu::{Binding, BindingKind};
        let mut b = vec![Binding::one(BindingKind::Uniform)];
        b.extend(std::iter::repeat_n(Binding::one(BindingKind::Storage), MAX_CHUNKS as usize));
        b
    }

    /// Bytes resident (header and chunks).
    pub fn bytes(&self) -> u64 {
        self.chunks.iter().map(|c| c.size).sum::<u64>() + self.grid.size
    }

    /// Descriptor writes: the header at `first`, chunk i at `first + 1 + i` (unused chunk slots
    /// repeat chunk 0: every binding must name a buffer).
    pub fn writes(&self, first: u32) -> Vec<crate::gpu::Write<'_>> {
        let mut w = vec![crate::gpu::Write::Buffer(first, &self.grid)];
        for i in 0..MAX_CHUNKS {
            let chunk = self.chunks.get(i as usize).unwrap_or(&self.chunks[0]);
            w.push(crate::gpu::Write::Buffer(first + 1 + i, chunk));
        }
        w
    }
}
