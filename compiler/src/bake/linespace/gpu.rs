//! The line-space bake on a GPU, through Vulkan compute (`kiln-gpubake`): the binary and PNMT
//! variants, the same bytes as the CPU bake (`shafts.rs`).
//!
//! Three kernels per batch of cells (`compiler/shaders/`): `linespace_prepare` takes a thread
//! per cell triangle and makes what depends on it alone: its separations from each face, and,
//! clipped to the widened cell, its key bounds and fallback records per pair;
//! `linespace_search` takes a thread per (cell, shaft) through the cell's triangles in list
//! order, decides the shaft with the separating-axis sweep in the CPU's double-precision
//! arithmetic (sign masks, then the fraction test; `geometry.rs`), and fills it as `Fills::fill`
//! does (bit, nearest midpoint hits from either end, fallback triangles by key);
//! `linespace_records` encodes each filled shaft's two records at its rank.
//!
//! Batches are pipelined: while the GPU searches one, the CPU copies the records of the one
//! before out of the mapped memory the GPU wrote them to.
//!
//! Not on the GPU: candidate lists and pre-illuminated radiance (the CPU bakes those), and
//! records with texture coordinates where the scene has any (binary16 rounding is not
//! reproduced); [`supports`] says which.

use kiln_format::gpu::{BakeCell, BakeParams};
use kiln_format::linespace::index::shafts_per_voxel;
use kiln_format::linespace::{PnmtLayout, Variants, words_per_slot};
use kiln_gpubake::{Buffer, Compute, Kernel, Memory, Options};
use rayon::prelude::*;

use super::shafts::HitAttributes;
use crate::exit::{CliError, CliResult};
use crate::progress::Progress;

const PREPARE: &[u8] = include_bytes!("../../../shaders/spirv/linespace_prepare.comp.spv");
const SEARCH: &[u8] = include_bytes!("../../../shaders/spirv/linespace_search.comp.spv");
const RECORDS: &[u8] = include_bytes!("../../../shaders/spirv/linespace_records.comp.spv");

/// The most bytes of buffers a [`GpuBaker`] keeps between bakes.
const POOL_BYTES: u64 = 2 << 30;

/// Threads of a search workgroup (`linespace_search.comp`'s local size).
const SEARCH_GROUP: u32 = 128;

/// Bytes of one shaft's two ends as the search leaves them for the records (3 words an end).
const END_BYTES: u64 = 24;

/// The scratch of ends one batch may use: batches are cut to it (1,193 cells at N = 5). Smaller
/// batches need less pinned host memory for their records, whose allocation the driver charges
/// by the byte (0.5 ms a MiB on the H200 machine), but each costs submissions and a partly
/// idle GPU: at 32 MiB the teapot's 32³ bake took 1.1×, the 72³ dragon's 1.4× as long.
const BATCH_SCRATCH: u64 = 1 << 28;

/// Bytes of one cell triangle's separations from the faces (6 faces × 13 axes × 4 doubles).
const FACE_SEP_BYTES: u64 = 6 * 13 * 4 * 8;

/// Cell triangles one batch may hold (each has its separations, key bounds and fallbacks in GPU
/// memory for the batch).
const BATCH_CELL_TRIANGLES: usize = 1 << 22;

/// A GPU ready to bake line spaces.
#[derive(Debug)]
pub struct GpuBaker {
    /// The thread freeing buffers the pool does not keep.
    releasing: std::sync::Mutex<Option<std::thread::JoinHandle<()>>>,
    /// Buffers of earlier bakes (or of [`GpuBaker::warm`]), reused by later ones: allocating
    /// GPU and pinned host memory costs the driver about 0.5 ms a MiB on the H200 machine, as
    /// much as the bake of the teapot's 32³ line space itself.
    pool: std::sync::Mutex<Vec<Buffer>>,
    // Kernels before the device: fields drop in order.
    prepare: Kernel,
    search: Kernel,
    records: Kernel,
    compute: Compute,
}

impl GpuBaker {
    /// Opens a GPU (or, with `options.allow_cpu`, a CPU implementation) and builds the kernels.
    pub fn new(options: &Options) -> Result<GpuBaker, String> {
        let compute = Compute::new(options).map_err(|e| e.0)?;
        let prepare = compute.kernel(PREPARE, 8).map_err(|e| e.0)?;
        let search = compute.kernel(SEARCH, 9).map_err(|e| e.0)?;
        let records = compute.kernel(RECORDS, 7).map_err(|e| e.0)?;
        Ok(GpuBaker {
            releasing: std::sync::Mutex::new(None),
            pool: std::sync::Mutex::new(Vec::new()),
            prepare,
            search,
            records,
            compute,
        })
    }

    /// The device's name.
    pub fn device(&self) -> &str {
        self.compute.name()
    }

    /// Validation errors so far (with `Options::validate`).
    pub fn validation_errors(&self) -> u32 {
        self.wait_released();
        self.compute.validation_errors()
    }

    /// Allocates what a bake at shaft resolution `n` of up to [`BATCH_SCRATCH`] of ends a
    /// batch and half its shafts filled needs, into the pool, so that the first bake finds
    /// its largest buffers made, and runs the kernels once (a process that will bake can do this
    /// while it does other work; the bench does it when it opens the GPU, and says how long that
    /// took).
    pub fn warm(&self, n: u32, layout: PnmtLayout) -> Result<(), String> {
        let shafts = shafts_per_voxel(n.clamp(1, 8)) as u64;
        let cells = (BATCH_SCRATCH.min(self.compute.max_buffer()) / (shafts * END_BYTES)).max(1);
        let records = cells * shafts * 2 * layout.words() as u64 * 4 * 3 / 5;
        let made = [
            (cells * shafts * END_BYTES, Memory::Device),
            (records, Memory::Device),
            (records, Memory::Readback),
            (records, Memory::Readback),
        ]
        .into_iter()
        .map(|(size, memory)| self.compute.buffer(size, memory))
        .collect::<kiln_gpubake::Result<Vec<_>>>()
        .map_err(|e| e.0)?;
        self.pool.lock().unwrap_or_else(|e| e.into_inner()).extend(made);
        self.run_empty(n, layout).map_err(|e| e.0)
    }

    /// Runs the three kernels once over a cell without triangles, so that whatever the driver
    /// does on a pipeline's first use happens now rather than in the first bake.
    fn run_empty(&self, n: u32, layout: PnmtLayout) -> kiln_gpubake::Result<()> {
        let n = n.clamp(1, 8);
        let shafts = shafts_per_voxel(n);
        let groups = shafts.div_ceil(SEARCH_GROUP);
        let c = &self.compute;
        let upload = |bytes: &[u8]| -> kiln_gpubake::Result<Buffer> {
            let mut b = c.buffer(bytes.len() as u64, Memory::Upload)?;
            b.write(bytes)?;
            Ok(b)
        };
        let params = bake_params(n, layout, true, 0.0);
        let cell = BakeCell { cell: 1.0, inv_cell: 1.0, ..Default::default() };
        let params = upload(bytemuck::bytes_of(&params))?;
        let cells = upload(bytemuck::bytes_of(&cell))?;
        let empty = c.buffer(4, Memory::Device)?;
        let ends = c.buffer(shafts as u64 * END_BYTES, Memory::Device)?;
        let bits = c.buffer(words_per_slot(n) as u64 * 4, Memory::Device)?;
        let tests = c.buffer(groups as u64 * 4, Memory::Device)?;
        c.run(|r| {
            r.dispatch(
                &self.prepare,
                &[&params, &cells, &empty, &empty, &empty, &empty, &empty, &empty],
                [1, 1, 1],
            )?;
            r.dispatch(
                &self.search,
                &[&params, &cells, &empty, &empty, &empty, &empty, &ends, &bits, &tests],
                [groups, 1, 1],
            )?;
            r.dispatch(&self.records, &[&params, &cells, &empty, &empty, &ends, &bits, &empty], [1, 1, 1])
        })
    }

    /// A buffer of at least `size` bytes in `memory`: the smallest such from the pool if it is
    /// at most twice as large (or 2 MiB), else a new one.
    fn take(&self, size: u64, memory: Memory) -> kiln_gpubake::Result<Buffer> {
        let mut pool = self.pool.lock().unwrap_or_else(|e| e.into_inner());
        let best = pool
            .iter()
            .enumerate()
            // Not a buffer much larger than asked: a small request would take a large one that a
            // later request of its size then has to allocate anew.
            .filter(|(_, b)| b.memory() == memory && b.size() >= size && b.size() <= size.max(1 << 20) * 2)
            .min_by_key(|(_, b)| b.size())
            .map(|(i, _)| i);
        match best {
            Some(i) => Ok(pool.swap_remove(i)),
            None => {
                drop(pool);
                self.compute.buffer(size, memory)
            }
        }
    }

    /// Keeps `buffers` for later bakes, up to [`POOL_BYTES`] (the largest first); frees the rest
    /// on another thread.
    fn keep(&self, buffers: Vec<Buffer>) {
        let mut pool = self.pool.lock().unwrap_or_else(|e| e.into_inner());
        pool.extend(buffers);
        pool.sort_by_key(|b| std::cmp::Reverse(b.size()));
        let mut total = 0;
        let keep = pool.iter().take_while(|b| {
            total += b.size();
            total <= POOL_BYTES
        });
        let kept = keep.count();
        let extra = pool.split_off(kept);
        drop(pool);
        self.release(extra);
    }

    /// Frees `buffers` on another thread (the previous batch of them first).
    fn release(&self, buffers: Vec<Buffer>) {
        self.wait_released();
        let handle = std::thread::spawn(move || drop(buffers));
        *self.releasing.lock().unwrap_or_else(|e| e.into_inner()) = Some(handle);
    }

    /// Waits until the buffers handed to [`Self::release`] are freed.
    pub fn wait_released(&self) {
        if let Some(h) = self.releasing.lock().unwrap_or_else(|e| e.into_inner()).take() {
            let _ = h.join();
        }
    }
}

impl Drop for GpuBaker {
    fn drop(&mut self) {
        // The buffers must go before the device they were made on.
        self.wait_released();
    }
}

/// Where `kiln compile` bakes the line space (`--line-space-device`). The file is the same
/// either way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum BakeDevice {
    /// The GPU where one opens and the bake is large enough to gain from it (see [`AUTO_MIN_WORK`]),
    /// else the CPU.
    #[default]
    Auto,
    /// The CPU.
    Cpu,
    /// The GPU; an error if none opens.
    Gpu,
}

/// The least work (Σ over occupied cells of triangles × shafts) for which `auto` opens a GPU:
/// below it the CPU bake takes tens of milliseconds, about what opening a GPU costs (Table 1's
/// rows 1 and 2, 2.5 M and 6.2 M, bake faster on the H200 machine's 16 CPU threads than on its
/// GPU; row 3, 194 M, twice as fast on the GPU).
pub const AUTO_MIN_WORK: u64 = 50_000_000;

static CHOICE: std::sync::Mutex<BakeDevice> = std::sync::Mutex::new(BakeDevice::Auto);
static OPENED: std::sync::OnceLock<Result<std::sync::Mutex<GpuBaker>, String>> = std::sync::OnceLock::new();

/// Sets where later bakes of this process run.
pub fn choose(device: BakeDevice) {
    *CHOICE.lock().unwrap_or_else(|e| e.into_inner()) = device;
}

/// The process's GPU, opened (and warmed for shaft resolution `n`) on first use.
fn opened(n: u32, layout: PnmtLayout) -> &'static Result<std::sync::Mutex<GpuBaker>, String> {
    OPENED.get_or_init(|| {
        let gpu = GpuBaker::new(&Options::default())?;
        // A bake without the warm buffers allocates its own.
        let _ = gpu.warm(n, layout);
        Ok(std::sync::Mutex::new(gpu))
    })
}

/// Whether the current choice is `gpu` (a failure of the GPU bake is then an error, not a
/// fallback to the CPU).
pub fn required() -> bool {
    *CHOICE.lock().unwrap_or_else(|e| e.into_inner()) == BakeDevice::Gpu
}

/// Whether a bake of `work` runs on a GPU under the current choice (if one opens).
fn wants_gpu(work: u64) -> bool {
    match *CHOICE.lock().unwrap_or_else(|e| e.into_inner()) {
        BakeDevice::Cpu => false,
        BakeDevice::Gpu => true,
        BakeDevice::Auto => work >= AUTO_MIN_WORK,
    }
}

/// Opens the GPU on another thread if a bake of about `work` at resolution `n` will want it,
/// so that opening it (half a second on the H200 machine) overlaps the stages before the line
/// space.
pub fn open_early(work: u64, n: u32, layout: PnmtLayout) {
    if wants_gpu(work) && OPENED.get().is_none() {
        let handle = std::thread::spawn(move || {
            opened(n, layout);
        });
        *OPENING.lock().unwrap_or_else(|e| e.into_inner()) = Some(handle);
    }
}

/// The thread [`open_early`] started.
static OPENING: std::sync::Mutex<Option<std::thread::JoinHandle<()>>> = std::sync::Mutex::new(None);

/// Waits for the threads of the GPU bake (opening the GPU, freeing buffers) to finish, so that
/// none is inside the driver when the process exits.
pub fn finish() {
    if let Some(h) = OPENING.lock().unwrap_or_else(|e| e.into_inner()).take() {
        let _ = h.join();
    }
    if let Some(Ok(gpu)) = OPENED.get() {
        gpu.lock().unwrap_or_else(|e| e.into_inner()).wait_released();
    }
}

/// The GPU a bake of `work` (Σ triangles × shafts over the occupied cells) at resolution `n`
/// runs on under the current choice, opened once per process; `None`: the CPU.
pub fn for_bake(
    work: u64,
    n: u32,
    layout: PnmtLayout,
) -> CliResult<Option<std::sync::MutexGuard<'static, GpuBaker>>> {
    if !wants_gpu(work) {
        return Ok(None);
    }
    match opened(n, layout) {
        Ok(gpu) => Ok(Some(gpu.lock().unwrap_or_else(|e| e.into_inner()))),
        // The machine lacks what was asked for: unsupported (exit 3), as an unsupported input is.
        Err(e) if required() => Err(CliError::new(
            crate::exit::Exit::Unsupported,
            format!("--line-space-device gpu: no GPU for the line-space bake ({e}); use auto or cpu"),
        )),
        Err(_) => Ok(None),
    }
}

/// Whether the GPU bake makes these variants (binary, PNMT) in this layout for a scene with
/// (`has_uvs`) or without texture coordinates (no candidates or pre-illumination; records with
/// texture coordinates only where the scene has none).
pub fn supports(variants: u32, layout: PnmtLayout, has_uvs: bool) -> bool {
    variants & (Variants::CANDIDATES | Variants::PREILLUM) == 0 && (!layout.stores_uv() || !has_uvs)
}

/// The work of a line-space bake the GPU makes, Σ over the occupied cells of triangles × shafts
/// (`cell_triangles()` entries in the voxel grid's lists at resolution `n`), the measure of
/// whether opening a GPU pays; `None` where the GPU makes none of `variants` ([`supports`]).
pub fn planned_work(
    variants: u32,
    layout: PnmtLayout,
    has_uvs: bool,
    n: u32,
    cell_triangles: impl FnOnce() -> usize,
) -> Option<u64> {
    (variants != 0 && n > 0 && supports(variants, layout, has_uvs))
        .then(|| cell_triangles() as u64 * shafts_per_voxel(n) as u64)
}

fn gpu_err(e: kiln_gpubake::Error) -> CliError {
    CliError::input(format!(
        "the GPU line-space bake failed: {e} (bake on the CPU with --line-space-device cpu)"
    ))
}

/// The kernels' settings for shaft resolution `n`, records in `layout` (tracked if `records`),
/// the grid margin `margin` in cells.
fn bake_params(n: u32, layout: PnmtLayout, records: bool, margin: f64) -> BakeParams {
    let s = 1.0 / n as f64;
    let centre: Vec<f64> = (0..8).map(|i| if i < n { (i as f64 + 0.5) / n as f64 } else { 0.0 }).collect();
    BakeParams {
        n,
        n2: n * n,
        n4: n * n * n * n,
        shafts: shafts_per_voxel(n),
        layout_code: layout.code(),
        words: layout.words() as u32,
        records: records as u32,
        s,
        half_s: 0.5 * s,
        margin,
        centre_lo: [centre[0], centre[1], centre[2], centre[3]],
        centre_hi: [centre[4], centre[5], centre[6], centre[7]],
        ..Default::default()
    }
}

/// Uploads `data` into a new device buffer through a mapped one: the pair, for a copy command.
fn staged<T: bytemuck::Pod>(compute: &Compute, data: &[T]) -> kiln_gpubake::Result<(Buffer, Buffer)> {
    let bytes = std::mem::size_of_val(data) as u64;
    let device = compute.buffer(bytes, Memory::Device)?;
    let mut host = compute.buffer(bytes, Memory::Upload)?;
    host.write(data)?;
    Ok((host, device))
}

/// A batch's buffers the CPU fills or reads: two sets, so that one batch's records are copied
/// out while the GPU works on the next.
struct HostSide {
    cells: Buffer,
    cell_tris: Buffer,
    bits: Buffer,
    tests: Buffer,
    records: Buffer,
}

/// Bakes the binary (and, if `pnmt`, PNMT) line space of the occupied `cells` into `out`'s
/// `bits`, `ranks` and `pnmt` (appended in cell order, as the CPU bake lays them out), with the
/// (triangle, shaft) pairs the separations left to decide in `tests` and the filled shafts
/// lacking a record in `pnmt_missing`.
pub(super) fn bake(
    gpu: &GpuBaker,
    cells: &super::Cells,
    layout: PnmtLayout,
    pnmt: bool,
    progress: &Progress,
    out: &mut super::BakedLineSpace,
) -> CliResult<()> {
    let super::Cells { attrs, header, local, voxel_offsets, voxel_triangles, occupied, n, margin } = *cells;
    let compute = &gpu.compute;
    let shafts = shafts_per_voxel(n);
    let wps = words_per_slot(n);
    let words = layout.words() as u32;
    let params = bake_params(n, layout, pnmt, margin);
    // Every triangle's grid-local corners (doubles) and world corners, vertex normals and
    // material (floats), in the scene's order.
    let corners: Vec<f64> = local.iter().flat_map(|t| t.iter().flat_map(|p| p.to_array())).collect();
    let max_material = u32::from(layout.max_material());
    let tri_data: Vec<f32> = (0..attrs.triangles.len() as u32)
        .into_par_iter()
        .flat_map_iter(|t| {
            let c = attrs.corners(t);
            let nrm = attrs.triangles[t as usize].map(|i| attrs.vertices[i as usize].normal);
            let m = u32::from(attrs.material(t)).min(max_material);
            let mut d = [0f32; 20];
            for k in 0..3 {
                d[3 * k..3 * k + 3].copy_from_slice(&c[k].to_array());
                d[9 + 3 * k..12 + 3 * k].copy_from_slice(&nrm[k]);
            }
            // Materials are below 2^16: exact as floats.
            d[18] = m as f32;
            d
        })
        .collect();
    // Batches: cells up to the scratch's and the triangle lists' budgets, every buffer a kernel
    // binds within the device's storage-buffer range.
    let limit = BATCH_SCRATCH.min(compute.max_buffer());
    // (A batch's cells are the search's second dispatch dimension: at most 65,535.)
    let max_cells = (limit / (shafts as u64 * END_BYTES)).clamp(1, 65_535) as usize;
    // The largest per-triangle buffer: the separations from the faces.
    let per_cell_triangle = FACE_SEP_BYTES.max(30 * 8u64.max(4 * words as u64));
    let max_tris = BATCH_CELL_TRIANGLES.min((limit / per_cell_triangle) as usize);
    let cell_len = |c: usize| (voxel_offsets[c + 1] - voxel_offsets[c]) as usize;
    let mut batches = Vec::new();
    let mut start = 0;
    while start < occupied.len() {
        let (mut end, mut tris) = (start, 0);
        while end < occupied.len() && end - start < max_cells {
            let len = cell_len(occupied[end]);
            if end > start && tris + len > max_tris {
                break;
            }
            tris += len;
            end += 1;
        }
        batches.push((start..end, tris));
        start = end;
    }
    let most_cells = batches.iter().map(|b| b.0.len()).max().unwrap_or(0) as u64;
    let most_tris = batches.iter().map(|b| b.1).max().unwrap_or(0) as u64;
    let record_limit = (most_cells * shafts as u64 * 2 * words as u64 * 4).min(compute.max_buffer());
    let search_groups = shafts.div_ceil(SEARCH_GROUP);
    // The per-batch buffers' sizes (the largest batch's).
    let cells_size = most_cells * size_of::<BakeCell>() as u64;
    let cell_tris_size = most_tris * 4;
    let keys_size = most_tris * 30 * 8;
    let face_seps_size = most_tris * FACE_SEP_BYTES;
    let fallbacks_size = if pnmt { most_tris * 30 * words as u64 * 4 } else { 4 };
    let ends_size = most_cells * shafts as u64 * END_BYTES;
    let bits_size = most_cells * wps as u64 * 4;
    let tests_size = most_cells * search_groups as u64 * 4;
    // Every buffer a kernel binds within the device's storage-buffer range, every index within
    // 32 bits (a cell of millions of triangles, a scene of tens of millions, can exceed them).
    let max = compute.max_buffer();
    let sizes = [
        ("the scene's corners", corners.len() as u64 * 8),
        ("the scene's triangle data", tri_data.len() as u64 * 4),
        ("a batch's separations", face_seps_size),
        ("a batch's fallback records", fallbacks_size),
        ("a batch's ends", ends_size),
    ];
    if let Some((what, bytes)) = sizes.iter().find(|(_, b)| *b > max) {
        return Err(CliError::input(format!(
            "the GPU line-space bake cannot hold {what} ({} MiB, the device binds at most {} MiB); bake on the CPU (--line-space-device cpu) or raise --voxel-res",
            bytes >> 20,
            max >> 20
        )));
    }
    // KILN_GPU_TIMING=1: where the time goes, per phase, on stderr.
    let mut laps = Laps::new(std::env::var_os("KILN_GPU_TIMING").is_some());
    let timing = laps.on;
    let mut rank = 0u64;
    out.bits.reserve_exact(occupied.len() * wps);
    out.ranks.reserve_exact(occupied.len() * wps);
    let mut run = || -> kiln_gpubake::Result<()> {
        let (params_host, params_dev) = staged(compute, std::slice::from_ref(&params))?;
        let (corners_host, corners_dev) = staged(compute, &corners)?;
        let (tris_host, tris_dev) = staged(compute, &tri_data)?;
        compute.run(|c| {
            for (h, d) in
                [(&params_host, &params_dev), (&corners_host, &corners_dev), (&tris_host, &tris_dev)]
            {
                c.copy(h, d, h.size());
            }
            Ok(())
        })?;
        drop((params_host, corners_host, tris_host));
        laps.lap(4);
        let cells_dev = gpu.take(cells_size, Memory::Device)?;
        let cell_tris_dev = gpu.take(cell_tris_size, Memory::Device)?;
        let keys = gpu.take(keys_size, Memory::Device)?;
        let face_seps = gpu.take(face_seps_size, Memory::Device)?;
        let fallbacks = gpu.take(fallbacks_size, Memory::Device)?;
        let ends = gpu.take(ends_size, Memory::Device)?;
        let bits_dev = gpu.take(bits_size, Memory::Device)?;
        let tests_dev = gpu.take(tests_size, Memory::Device)?;
        // Records are written to GPU memory and copied to the host by a copy command: the
        // kernel writing them to host memory itself was slower by an order of magnitude.
        let mut records_dev = gpu.take(4, Memory::Device)?;
        let mut host: Vec<HostSide> = (0..2.min(batches.len()))
            .map(|_| {
                Ok(HostSide {
                    cells: gpu.take(cells_size, Memory::Upload)?,
                    cell_tris: gpu.take(cell_tris_size, Memory::Upload)?,
                    bits: gpu.take(bits_size, Memory::Readback)?,
                    tests: gpu.take(tests_size, Memory::Readback)?,
                    records: gpu.take(4, Memory::Readback)?,
                })
            })
            .collect::<kiln_gpubake::Result<_>>()?;
        laps.lap(0);
        // The batch whose records are on their way: (its host side, records bytes, cells done).
        let mut in_flight: Option<(kiln_gpubake::Pending, usize, u64, usize)> = None;
        let mut cells_done = 0;
        let mut retired = Vec::new();
        for (i, (range, tris)) in batches.iter().enumerate() {
            let batch = &occupied[range.clone()];
            let side = i % 2;
            let first_tri = voxel_offsets[batch[0]] as usize;
            let mut cells = Vec::with_capacity(batch.len());
            for &c in batch {
                let cc = header.cell_coords(c);
                let w = header.cell_min(cc);
                cells.push(BakeCell {
                    gx: cc[0] as f64,
                    gy: cc[1] as f64,
                    gz: cc[2] as f64,
                    wx: w.x,
                    wy: w.y,
                    wz: w.z,
                    cell: header.cell,
                    inv_cell: 1.0 / header.cell,
                    tri_first: voxel_offsets[c] - first_tri as u32,
                    tri_count: cell_len(c) as u32,
                    ..Default::default()
                });
            }
            let h = &mut host[side];
            h.cells.write(&cells)?;
            // The occupied cells are in order, so their lists are one run of the voxel lists.
            h.cell_tris.write(&voxel_triangles[first_tri..first_tri + tris])?;
            let cells_bytes = std::mem::size_of_val(cells.as_slice()) as u64;
            let (bits_bytes, tests_bytes) =
                ((batch.len() * wps * 4) as u64, batch.len() as u64 * search_groups as u64 * 4);
            let groups = batch.len() as u32;
            let h = &host[side];
            let prepare = |c: &mut kiln_gpubake::Commands| {
                c.copy(&h.cells, &cells_dev, cells_bytes);
                c.copy(&h.cell_tris, &cell_tris_dev, *tris as u64 * 4);
                c.zero(&tests_dev, tests_bytes);
                c.dispatch(
                    &gpu.prepare,
                    &[
                        &params_dev,
                        &cells_dev,
                        &cell_tris_dev,
                        &corners_dev,
                        &tris_dev,
                        &keys,
                        &fallbacks,
                        &face_seps,
                    ],
                    [groups, 1, 1],
                )
            };
            if timing {
                // Timing: the preparation alone.
                laps.lap(2);
                compute.run(prepare)?;
                laps.lap(4);
            }
            // SAFETY: every buffer the commands use is declared before `search` and `in_flight`
            // (so outlives them, error paths included) and is neither read nor replaced before
            // `search` is waited for.
            let search = unsafe {
                compute.submit(|c| {
                    if !timing {
                        prepare(c)?;
                    }
                    c.dispatch(
                        &gpu.search,
                        &[
                            &params_dev,
                            &cells_dev,
                            &cell_tris_dev,
                            &keys,
                            &tris_dev,
                            &face_seps,
                            &ends,
                            &bits_dev,
                            &tests_dev,
                        ],
                        [search_groups, groups, 1],
                    )?;
                    c.copy(&bits_dev, &h.bits, bits_bytes);
                    c.copy(&tests_dev, &h.tests, tests_bytes);
                    c.to_host();
                    Ok(())
                })?
            };
            // Timing: the search alone (no overlap with the records before).
            let search = laps.alone(compute, search, 5)?;
            // While the GPU searches, the records of the batch before go out.
            if let Some((pending, prev, bytes, done)) = in_flight.take() {
                pending.wait()?;
                laps.lap(1);
                copy_out(&host[prev].records, bytes, words, layout, done as f64 / occupied.len() as f64, out);
                laps.lap(3);
            }
            search.wait()?;
            laps.lap(1);
            let h = &mut host[side];
            let batch_bits: &[u32] = bytemuck::cast_slice(&h.bits.bytes()[..bits_bytes as usize]);
            out.tests += bytemuck::cast_slice::<u8, u32>(&h.tests.bytes()[..tests_bytes as usize])
                .iter()
                .map(|&t| t as u64)
                .sum::<u64>();
            // Ranks, and each cell's first record in the batch (the batch's records are addressed
            // in 32 bits on the GPU: checked for the whole batch first).
            let batch_filled: u64 = batch_bits.iter().map(|w| w.count_ones() as u64).sum();
            if rank + batch_filled > u32::MAX as u64 {
                return Err(kiln_gpubake::Error(super::too_many().to_string()));
            }
            let first = rank;
            for (cell, words) in cells.iter_mut().zip(batch_bits.chunks_exact(wps)) {
                cell.record_base = (rank - first) as u32;
                rank = super::push_ranks(&mut out.ranks, words, rank)
                    .map_err(|e| kiln_gpubake::Error(e.to_string()))?;
            }
            let filled = rank - first;
            out.bits.extend_from_slice(batch_bits);
            cells_done += batch.len();
            laps.lap(8);
            if pnmt && filled > 0 {
                let record_bytes = filled * 2 * words as u64 * 4;
                // Sized to the records found with room for the batches to come (the fine rows of
                // seed 004's table fill half their shafts), not to the most a batch can hold:
                // the driver charges pinned memory by the byte. Outgrown buffers are freed with
                // the rest, at the end.
                let room = (record_bytes + record_bytes / 4)
                    .max(record_limit * 3 / 5)
                    .min(record_limit)
                    .max(record_bytes);
                if record_bytes > max {
                    return Err(kiln_gpubake::Error(format!(
                        "a batch's records ({} MiB) exceed what the device binds ({} MiB)",
                        record_bytes >> 20,
                        max >> 20
                    )));
                }
                if record_bytes > h.records.size() {
                    retired.push(std::mem::replace(&mut h.records, gpu.take(room, Memory::Readback)?));
                }
                if record_bytes > records_dev.size() {
                    retired.push(std::mem::replace(&mut records_dev, gpu.take(room, Memory::Device)?));
                }
                laps.lap(7);
                h.cells.write(&cells)?;
                let h = &host[side];
                // SAFETY: as for the search; the records buffers are replaced only after the
                // batch before has been waited for (`in_flight`), and read only after this one.
                let records = unsafe {
                    compute.submit(|c| {
                        c.copy(&h.cells, &cells_dev, cells_bytes);
                        c.dispatch(
                            &gpu.records,
                            &[&params_dev, &cells_dev, &fallbacks, &tris_dev, &ends, &bits_dev, &records_dev],
                            [groups, 1, 1],
                        )?;
                        c.copy(&records_dev, &h.records, record_bytes);
                        c.to_host();
                        Ok(())
                    })?
                };
                let records = laps.alone(compute, records, 6)?;
                in_flight = Some((records, side, record_bytes, cells_done));
            }
            laps.lap(2);
            progress.inc(batch.len() as u64);
        }
        if let Some((pending, prev, bytes, done)) = in_flight.take() {
            pending.wait()?;
            laps.lap(1);
            copy_out(&host[prev].records, bytes, words, layout, done as f64 / occupied.len() as f64, out);
            laps.lap(3);
        }
        // Kept for the next bake (freeing hundreds of MiB of GPU and pinned memory, what the
        // pool does not keep, takes the driver milliseconds: on another thread).
        let mut done: Vec<Buffer> = vec![
            params_dev,
            corners_dev,
            tris_dev,
            cells_dev,
            cell_tris_dev,
            keys,
            face_seps,
            fallbacks,
            ends,
            bits_dev,
            tests_dev,
            records_dev,
        ];
        for h in host {
            done.extend([h.cells, h.cell_tris, h.bits, h.tests, h.records]);
        }
        done.extend(retired);
        gpu.keep(done);
        Ok(())
    };
    let result = run().map_err(gpu_err);
    if laps.on {
        let phases = laps.phases;
        eprintln!(
            "GPU bake, ms: buffers {:.1}, uploads and preparation {:.1}, search {:.1}, records {:.1}, other waits {:.1}, CPU between kernels {:.1} (ranks {:.1}, record buffers {:.1}), copying records out {:.1}",
            phases[0],
            phases[4],
            phases[5],
            phases[6],
            phases[1],
            phases[2] + phases[7] + phases[8],
            phases[8],
            phases[7],
            phases[3]
        );
    }
    result
}

/// Wall time per phase of a bake, when on (`KILN_GPU_TIMING`).
struct Laps {
    on: bool,
    phases: [f64; 9],
    clock: std::time::Instant,
}

impl Laps {
    fn new(on: bool) -> Laps {
        Laps { on, phases: [0.0; 9], clock: std::time::Instant::now() }
    }

    /// Adds the time since the last lap to `phase`.
    fn lap(&mut self, phase: usize) {
        if self.on {
            self.phases[phase] += self.clock.elapsed().as_secs_f64() * 1e3;
            self.clock = std::time::Instant::now();
        }
    }

    /// When on, waits for `work` and counts it as `phase` alone (no overlap with what follows):
    /// returns work already done.
    fn alone<'a>(
        &mut self,
        compute: &'a Compute,
        work: kiln_gpubake::Pending<'a>,
        phase: usize,
    ) -> kiln_gpubake::Result<kiln_gpubake::Pending<'a>> {
        if !self.on {
            return Ok(work);
        }
        self.lap(2);
        work.wait()?;
        self.lap(phase);
        // SAFETY: no commands, no buffers.
        unsafe { compute.submit(|_| Ok(())) }
    }
}

/// Appends the first `bytes` of `records` (a batch's records, `words` a record) to `out.pnmt`,
/// in parallel, counting the filled shafts lacking a record; `done` is the fraction of the cells
/// baked once these are appended (the vector's growth is extrapolated from it).
fn copy_out(
    records: &Buffer,
    bytes: u64,
    words: u32,
    layout: PnmtLayout,
    done: f64,
    out: &mut super::BakedLineSpace,
) {
    let recs: &[u32] = bytemuck::cast_slice(&records.bytes()[..bytes as usize]);
    let shaft = 2 * words as usize;
    let pieces: Vec<&[u32]> = recs.chunks(shaft << 14).collect();
    super::append_par(&mut out.pnmt, &pieces, |p| p.iter().copied(), done);
    out.pnmt_missing += pieces
        .par_iter()
        .map(|p| {
            p.chunks_exact(shaft)
                .filter(|r| !layout.is_some(&r[..]) || !layout.is_some(&r[words as usize..]))
                .count() as u64
        })
        .sum::<u64>();
}
