//! The voxel grid and line-space stages (seed 004, made exact and sparse): voxelize, then fill
//! the shafts of every non-empty cell in parallel, then lay the results out as sections.

pub mod estimate;
mod geometry;
pub mod gpu;
mod segment;
mod shafts;
mod simd;
mod span;
pub mod stages;
pub mod voxelize;

use glam::{DVec3, Vec2, Vec3};
use kiln_format::linespace::index::MAX_SHAFT_RES;
use kiln_format::linespace::{GridHeader, MAX_CANDIDATE_CELL_TRIANGLES, NO_SLOT, PnmtLayout, Variants};
use kiln_format::sections::Vertex;
use rayon::prelude::*;

pub use shafts::{HitAttributes, Shade};

use crate::exit::{CliError, CliResult};
use crate::progress::Progress;

/// The baked grid and line space, ready to be written.
#[derive(Debug, Clone, Default)]
pub struct BakedLineSpace {
    /// Header.
    pub header: GridHeader,
    /// Cell triangle list offsets.
    pub voxel_offsets: Vec<u32>,
    /// Cell triangle lists.
    pub voxel_triangles: Vec<u32>,
    /// Slot per cell.
    pub slots: Vec<u32>,
    /// Shaft bits.
    pub bits: Vec<u32>,
    /// Ranks per bit word.
    pub ranks: Vec<u32>,
    /// Candidate offsets.
    pub candidate_offsets: Vec<u32>,
    /// Candidate entries.
    pub candidates: Vec<u32>,
    /// PNMT records, in the header's layout.
    pub pnmt: Vec<u32>,
    /// Pre-illuminated radiance per filled shaft.
    pub preillum: Vec<[u16; 8]>,
    /// (Triangle, shaft) pairs tested exactly by separating axes (spanning triangles decide
    /// theirs in closed form, uncounted).
    pub tests: u64,
    /// Filled shafts whose PNMT sample rays all missed (no record).
    pub pnmt_missing: u64,
    /// The GPU that baked the shafts (`None`: the CPU).
    pub device: Option<String>,
    /// Wall time of voxelization, ms.
    pub voxel_ms: f64,
    /// Wall time of the whole bake, ms.
    pub total_ms: f64,
}

impl BakedLineSpace {
    /// How the PNMT records are stored.
    pub fn pnmt_layout(&self) -> PnmtLayout {
        self.header.pnmt_records().unwrap_or_default()
    }
}

/// Scene attributes for PNMT records, over triangles in stored (BVH) order.
#[derive(Debug)]
pub struct SceneAttributes<'a> {
    /// Vertices.
    pub vertices: &'a [Vertex],
    /// Texture coordinates (may be empty).
    pub uvs: &'a [[f32; 2]],
    /// Triangles in stored order.
    pub triangles: &'a [[u32; 3]],
    /// Material per stored triangle.
    pub materials: &'a [u32],
}

impl HitAttributes for SceneAttributes<'_> {
    fn corners(&self, t: u32) -> [Vec3; 3] {
        self.triangles[t as usize].map(|i| Vec3::from(self.vertices[i as usize].position))
    }
    fn normal(&self, t: u32, u: f32, v: f32) -> Vec3 {
        let [a, b, c] = self.triangles[t as usize].map(|i| Vec3::from(self.vertices[i as usize].normal));
        let n = a * (1.0 - u - v) + b * u + c * v;
        if n.is_finite() && n != Vec3::ZERO {
            return n;
        }
        let [p, q, r] = self.corners(t);
        let g = (q - p).cross(r - p);
        if g.is_finite() && g != Vec3::ZERO { g } else { Vec3::Z }
    }
    fn uv(&self, t: u32, u: f32, v: f32) -> Vec2 {
        if self.uvs.is_empty() {
            return Vec2::ZERO;
        }
        let [a, b, c] = self.triangles[t as usize].map(|i| Vec2::from(self.uvs[i as usize]));
        a * (1.0 - u - v) + b * u + c * v
    }
    fn material(&self, t: u32) -> u16 {
        self.materials[t as usize].min(u16::MAX as u32 - 1) as u16
    }
    fn corner_normals(&self, t: u32) -> Option<[Vec3; 3]> {
        Some(self.triangles[t as usize].map(|i| Vec3::from(self.vertices[i as usize].normal)))
    }
}

/// Bakes the line space over `voxels` (the voxel grid in `attrs`' triangle order, which took
/// `voxel_ms` to build) at shaft resolution `n` with `variants` (0: grid only), PNMT records
/// in `layout`; on `gpu` where it is given and makes these variants ([`gpu::supports`]), else
/// on the CPU.
#[allow(clippy::too_many_arguments)]
pub fn bake(
    gpu: Option<&gpu::GpuBaker>,
    attrs: &SceneAttributes,
    voxels: voxelize::Voxels,
    voxel_ms: f64,
    n: u32,
    variants: u32,
    layout: PnmtLayout,
    shade: Option<&Shade<'_>>,
    progress: &Progress,
) -> CliResult<BakedLineSpace> {
    let start = std::time::Instant::now();
    let voxelize::Voxels { mut header, local, offsets: voxel_offsets, triangles: voxel_triangles } = voxels;
    let cells = header.cell_count() as usize;
    let cell_len = |c: usize| (voxel_offsets[c + 1] - voxel_offsets[c]) as usize;
    let mut out = BakedLineSpace { voxel_ms, ..Default::default() };
    if variants == 0 {
        out.total_ms = voxel_ms;
        out.header = header;
        out.voxel_offsets = voxel_offsets;
        out.voxel_triangles = voxel_triangles;
        return Ok(out);
    }
    let variants = variants | Variants::BINARY;
    if !(1..=MAX_SHAFT_RES).contains(&n) {
        return Err(CliError::usage(format!("shaft resolution {n} is outside 1..=8")));
    }
    let candidates = variants & Variants::CANDIDATES != 0;
    let pnmt = variants & Variants::PNMT != 0;
    let shade = if variants & Variants::PREILLUM != 0 {
        Some(shade.ok_or_else(|| {
            CliError::input("the pre-illuminated line space needs the scene's lights and BVH")
        })?)
    } else {
        None
    };
    if candidates && header.max_cell_triangles > MAX_CANDIDATE_CELL_TRIANGLES {
        return Err(CliError::input(format!(
            "a cell holds {} triangles, more than the {MAX_CANDIDATE_CELL_TRIANGLES} candidate lists can address; raise --voxel-res",
            header.max_cell_triangles
        )));
    }
    header.shaft_res = n;
    header.variants = variants;
    header.pnmt_layout = layout.code();
    let occupied: Vec<usize> = (0..cells).filter(|&c| cell_len(c) > 0).collect();
    let mut slots = vec![NO_SLOT; cells];
    for (s, &c) in occupied.iter().enumerate() {
        slots[c] = s as u32;
    }
    header.slots = occupied.len() as u32;
    let margin_local = header.margin / header.cell;
    progress.count("line space: cells", occupied.len() as u64);
    let cells = Cells {
        attrs,
        header: &header,
        local: &local,
        voxel_offsets: &voxel_offsets,
        voxel_triangles: &voxel_triangles,
        occupied: &occupied,
        n,
        margin: margin_local,
    };
    if let Some(gpu) = gpu.filter(|_| gpu::supports(variants, layout, !attrs.uvs.is_empty())) {
        gpu::bake(gpu, &cells, layout, pnmt, progress, &mut out)?;
        out.device = Some(gpu.device().to_string());
    } else {
        bake_on_cpu(&cells, (candidates, pnmt, layout), shade, progress, &mut out)?;
    }
    header.filled =
        out.ranks.last().map_or(0, |&r| r as u64) + out.bits.last().map_or(0, |w| w.count_ones() as u64);
    out.candidates.shrink_to_fit();
    out.candidate_offsets.shrink_to_fit();
    out.pnmt.shrink_to_fit();
    out.preillum.shrink_to_fit();
    header.entries = out.candidates.len() as u64;
    out.header = header;
    out.voxel_offsets = voxel_offsets;
    out.voxel_triangles = voxel_triangles;
    out.slots = slots;
    out.total_ms = voxel_ms + start.elapsed().as_secs_f64() * 1e3;
    Ok(out)
}

/// What a device bakes: the occupied cells of a voxel grid at shaft resolution `n`.
pub(super) struct Cells<'a> {
    /// The scene, triangles in the grid's order.
    pub attrs: &'a SceneAttributes<'a>,
    pub header: &'a GridHeader,
    /// Every triangle's grid-local corners.
    pub local: &'a [[DVec3; 3]],
    /// The cells' triangle lists.
    pub voxel_offsets: &'a [u32],
    pub voxel_triangles: &'a [u32],
    /// The cells with triangles, in slot order.
    pub occupied: &'a [usize],
    pub n: u32,
    /// The grid margin, in cells.
    pub margin: f64,
}

/// The CPU bake of the occupied `cells` into `out` (see [`bake`]), with candidates, PNMT
/// records in `layout` and pre-illumination (`shade`) as asked.
fn bake_on_cpu(
    cells: &Cells,
    (candidates, pnmt, layout): (bool, bool, PnmtLayout),
    shade: Option<&Shade<'_>>,
    progress: &Progress,
    out: &mut BakedLineSpace,
) -> CliResult<()> {
    let Cells { attrs, header, local, voxel_offsets, voxel_triangles, occupied, n, margin: margin_local } =
        *cells;
    // Cells are baked a chunk at a time and each chunk's parts appended to the sections before
    // the next: holding every cell's parts until the end doubled the bake's peak memory at the
    // fine rows of seed 004's table (gigabytes of PNMT records).
    let mut rank = 0u64;
    let mut cells_done = 0usize;
    for chunk in occupied.chunks(CELLS_PER_CHUNK) {
        cells_done += chunk.len();
        let done = cells_done as f64 / occupied.len() as f64;
        let per_cell: Vec<shafts::CellShafts> = chunk
            .par_iter()
            .map_init(shafts::Scratch::default, |scratch, &c| {
                let cc = header.cell_coords(c);
                let cell_min = DVec3::new(cc[0] as f64, cc[1] as f64, cc[2] as f64);
                let tris = &voxel_triangles[voxel_offsets[c] as usize..voxel_offsets[c + 1] as usize];
                let r = shafts::bake_cell(
                    tris,
                    local,
                    cell_min,
                    header.cell_min(cc),
                    header.cell,
                    n,
                    margin_local,
                    candidates,
                    pnmt,
                    layout,
                    attrs,
                    shade,
                    scratch,
                );
                progress.inc(1);
                r
            })
            .collect();
        for cell in &per_cell {
            out.tests += cell.tests;
            rank = push_ranks(&mut out.ranks, &cell.bits, rank)?;
            out.bits.extend_from_slice(&cell.bits);
        }
        if candidates {
            let mut base = out.candidates.len() as u64;
            let mut bases = Vec::with_capacity(per_cell.len());
            for c in &per_cell {
                bases.push(u32::try_from(base).map_err(|_| too_many())?);
                base += c.entries.len() as u64;
            }
            u32::try_from(base).map_err(|_| too_many())?;
            append_par(&mut out.candidates, &per_cell, |c| c.entries.iter().copied(), done);
            if out.candidate_offsets.is_empty() {
                out.candidate_offsets.push(0);
            }
            let cells: Vec<(&shafts::CellShafts, u32)> = per_cell.iter().zip(bases).collect();
            append_par(&mut out.candidate_offsets, &cells, list_ends, done);
        }
        if pnmt {
            append_par(&mut out.pnmt, &per_cell, |c| c.pnmt.iter().copied(), done);
            out.pnmt_missing += per_cell.iter().map(|c| c.pnmt_missing).sum::<u64>();
        }
        if shade.is_some() {
            append_par(&mut out.preillum, &per_cell, |c| c.preillum.iter().copied(), done);
        }
    }
    Ok(())
}

/// Appends to `ranks` the filled shafts before each of `words`, `rank` before the first;
/// returns the filled shafts after the last.
pub(super) fn push_ranks(ranks: &mut Vec<u32>, words: &[u32], mut rank: u64) -> CliResult<u64> {
    for &w in words {
        ranks.push(u32::try_from(rank).map_err(|_| too_many())?);
        rank += w.count_ones() as u64;
    }
    Ok(rank)
}

/// Fraction of filled shafts that no triangle meets by the one-shaft sweep test (0 while every
/// shaft is decided exactly; kept as a check of the bake), estimated from up to `samples` filled
/// shafts spread evenly over the line space.
pub fn false_fill_rate(attrs: &SceneAttributes, ls: &BakedLineSpace, samples: usize) -> f64 {
    let h = &ls.header;
    if h.filled == 0 {
        return 0.0;
    }
    let corners: Vec<[[f32; 3]; 3]> =
        attrs.triangles.iter().map(|t| t.map(|i| attrs.vertices[i as usize].position)).collect();
    let local = voxelize::local_triangles(h, &corners);
    let wps = kiln_format::linespace::words_per_slot(h.shaft_res);
    let step = (h.filled as usize / samples.max(1)).max(1);
    let mut picked = Vec::new();
    let mut rank = 0usize;
    for (c, &slot) in ls.slots.iter().enumerate() {
        if slot == NO_SLOT {
            continue;
        }
        for w in 0..wps {
            let mut word = ls.bits[slot as usize * wps + w];
            while word != 0 {
                let bit = word.trailing_zeros();
                word &= word - 1;
                if rank.is_multiple_of(step) {
                    picked.push((c, (w * 32) as u32 + bit));
                }
                rank += 1;
            }
        }
    }
    let margin = h.margin / h.cell;
    let false_fills = picked
        .par_iter()
        .filter(|&&(c, shaft)| {
            let cc = h.cell_coords(c);
            let tris = &ls.voxel_triangles[ls.voxel_offsets[c] as usize..ls.voxel_offsets[c + 1] as usize];
            !shafts::meets_exactly(
                tris,
                &local,
                DVec3::new(cc[0] as f64, cc[1] as f64, cc[2] as f64),
                shaft,
                h.shaft_res,
                margin,
            )
        })
        .count();
    false_fills as f64 / picked.len().max(1) as f64
}

/// A cell's candidate list ends, offset by where its entries start.
fn list_ends<'a>(
    &(cell, base): &'a (&'a shafts::CellShafts, u32),
) -> impl ExactSizeIterator<Item = u32> + 'a {
    cell.list_ends.iter().map(move |e| base + e)
}

/// Cells baked between two appends to the sections (see [`bake`]).
const CELLS_PER_CHUNK: usize = 1024;

/// Appends the parts of `items` (the elements `part` yields for each) to `out`, `done` the
/// fraction of all the parts that `out` will hold once these are appended; each part
/// written by its own task straight into its place in the vector's spare capacity, so that the
/// copying and the first touch of fresh pages are spread over the threads (one thread copying
/// the gigabytes of the fine rows was a third of the bake on 16 cores). Growing the vector moves
/// pages, not bytes, where the allocator maps large blocks (glibc's `mremap`).
fn append_par<'a, I: Sync, T: Copy + Send, P: ExactSizeIterator<Item = T>>(
    out: &mut Vec<T>,
    items: &'a [I],
    part: impl Fn(&'a I) -> P + Sync,
    done: f64,
) {
    let lens: Vec<usize> = items.iter().map(|i| part(i).len()).collect();
    let total: usize = lens.iter().sum();
    let needed = out.len() + total;
    if out.capacity() < needed {
        // Grown to what the parts so far extrapolate to (plus 5 %), not to twice the length as
        // `reserve` would: the vector is most of the bake's peak memory.
        let expected = (needed as f64 / done.clamp(1e-6, 1.0) * 1.05) as usize;
        out.reserve_exact(expected.max(needed) - out.len());
    }
    let mut parts = Vec::with_capacity(items.len());
    let mut rest = &mut out.spare_capacity_mut()[..total];
    for &n in &lens {
        let (p, tail) = rest.split_at_mut(n);
        parts.push(p);
        rest = tail;
    }
    parts.into_par_iter().zip(items.par_iter()).for_each(|(dst, item)| {
        let src = part(item);
        assert_eq!(src.len(), dst.len(), "a part changed its length");
        for (d, v) in dst.iter_mut().zip(src) {
            d.write(v);
        }
    });
    // SAFETY: the `total` elements after the length were each written above (every part's
    // iterator has exactly its slot's length, asserted).
    unsafe { out.set_len(out.len() + total) };
}

pub(super) fn too_many() -> CliError {
    CliError::input(
        "the line space has more than 2^32 filled shafts or candidate entries; lower --voxel-res or --shaft-res",
    )
}

#[cfg(test)]
mod tests {
    use super::append_par;

    /// Parts appended chunk after chunk, in parallel, against the standard library's concat.
    #[test]
    fn appending_in_parallel_concatenates() {
        let parts: Vec<Vec<u32>> =
            (0..300u32).map(|i| (0..(i * 37) % 101).map(|k| i * 1000 + k).collect()).collect();
        let mut out = Vec::new();
        for chunk in parts.chunks(7) {
            append_par(&mut out, chunk, |p| p.iter().copied(), 0.5);
        }
        assert_eq!(out, parts.concat());
    }
}
