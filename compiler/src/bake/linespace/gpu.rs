//! The line-space bake on a GPU, through Vulkan compute (`kiln-gpubake`): the binary and PNMT
//! variants, the same bytes as the CPU bake (`shafts.rs`).
//!
//! Two kernels per batch of cells (`compiler/shaders/`): `linespace_search` takes a workgroup
//! per (cell, face pair) through the cell's triangles in list order, decides every shaft with the
//! separating-axis sweep in the CPU's double-precision arithmetic (sign masks, then the fraction
//! test; `geometry.rs`), and fills the shafts met as `Fills::fill` does (bit, nearest midpoint
//! hits from either end, fallback triangles by key); `linespace_records` encodes each filled
//! shaft's two records at its rank. What depends on the clipped triangle alone (key bounds and
//! fallback records per pair, a few per triangle and cell) is made here on the CPU, in parallel,
//! with the CPU bake's own functions.
//!
//! Not on the GPU: candidate lists and pre-illuminated radiance (the CPU bakes those), and
//! records with texture coordinates where the scene has any (binary16 rounding is not
//! reproduced); [`supports`] says which.

use glam::DVec3;
use kiln_format::gpu::{BakeCell, BakeParams};
use kiln_format::linespace::index::shafts_per_voxel;
use kiln_format::linespace::{GridHeader, PnmtLayout, Variants, words_per_slot};
use kiln_gpubake::{Buffer, Compute, Kernel, Memory, Options};
use rayon::prelude::*;

use super::SceneAttributes;
use super::shafts::{HitAttributes, triangle_pair_data};
use crate::exit::{CliError, CliResult};
use crate::progress::Progress;

const SEARCH: &[u8] = include_bytes!("../../../shaders/spirv/linespace_search.comp.spv");
const RECORDS: &[u8] = include_bytes!("../../../shaders/spirv/linespace_records.comp.spv");

/// Bytes of one shaft's two ends in the search's scratch (`End` in `linespace_common.glsl`).
const END_BYTES: u64 = 64;

/// The scratch of ends one batch may use: batches are cut to it.
const BATCH_SCRATCH: u64 = 1 << 30;

/// Cell triangles one batch may hold (their key bounds and fallbacks are uploaded per batch).
const BATCH_CELL_TRIANGLES: usize = 1 << 22;

/// A GPU ready to bake line spaces.
#[derive(Debug)]
pub struct GpuBaker {
    // Kernels before the device: fields drop in order.
    search: Kernel,
    records: Kernel,
    compute: Compute,
}

impl GpuBaker {
    /// Opens a GPU (or, with `options.allow_cpu`, a CPU implementation) and builds the kernels.
    pub fn new(options: &Options) -> Result<GpuBaker, String> {
        let compute = Compute::new(options).map_err(|e| e.0)?;
        let search = compute.kernel(SEARCH, 9).map_err(|e| e.0)?;
        let records = compute.kernel(RECORDS, 7).map_err(|e| e.0)?;
        Ok(GpuBaker { search, records, compute })
    }

    /// The device's name.
    pub fn device(&self) -> &str {
        self.compute.name()
    }

    /// Validation errors so far (with `Options::validate`).
    pub fn validation_errors(&self) -> u32 {
        self.compute.validation_errors()
    }
}

/// Whether the GPU bake makes these variants (binary, PNMT) in this layout for this scene.
pub fn supports(variants: u32, layout: PnmtLayout, attrs: &SceneAttributes) -> bool {
    variants & (Variants::CANDIDATES | Variants::PREILLUM) == 0
        && (!layout.stores_uv() || attrs.uvs.is_empty())
}

fn gpu_err(e: kiln_gpubake::Error) -> CliError {
    CliError::input(format!(
        "the GPU line-space bake failed: {e} (bake on the CPU with --line-space-device cpu)"
    ))
}

/// A device buffer and the mapped buffer it is filled from or read back into.
struct Staged {
    device: Buffer,
    host: Buffer,
}

/// Uploads `data` into a new device buffer (through a staging buffer, copied by `run`'s
/// caller via the returned pair).
fn staged<T: bytemuck::Pod>(compute: &Compute, data: &[T]) -> kiln_gpubake::Result<Staged> {
    let bytes = std::mem::size_of_val(data) as u64;
    let device = compute.buffer(bytes, Memory::Device)?;
    let mut host = compute.buffer(bytes, Memory::Upload)?;
    host.write(data)?;
    Ok(Staged { device, host })
}

/// Bakes the binary (and, if `variants` has it, PNMT) line space of the `occupied` cells into
/// `bits`, `ranks` and `pnmt` (appended in cell order, as the CPU bake lays them out); returns
/// the (triangle, shaft) pairs the separations left to decide and the filled shafts lacking a
/// record.
#[allow(clippy::too_many_arguments)]
pub(super) fn bake(
    gpu: &GpuBaker,
    attrs: &SceneAttributes,
    header: &GridHeader,
    local: &[[DVec3; 3]],
    voxel_offsets: &[u32],
    voxel_triangles: &[u32],
    occupied: &[usize],
    n: u32,
    margin: f64,
    layout: PnmtLayout,
    pnmt: bool,
    progress: &Progress,
    out: &mut super::BakedLineSpace,
) -> CliResult<()> {
    let compute = &gpu.compute;
    let shafts = shafts_per_voxel(n);
    let wps = words_per_slot(n);
    let words = layout.words() as u32;
    let s = 1.0 / n as f64;
    let centre: Vec<f64> = (0..8).map(|i| if i < n { (i as f64 + 0.5) / n as f64 } else { 0.0 }).collect();
    let params = BakeParams {
        n,
        n2: n * n,
        n4: n * n * n * n,
        shafts,
        layout_code: layout.code(),
        words,
        records: pnmt as u32,
        s,
        half_s: 0.5 * s,
        margin,
        centre_lo: [centre[0], centre[1], centre[2], centre[3]],
        centre_hi: [centre[4], centre[5], centre[6], centre[7]],
        ..Default::default()
    };
    // Every triangle's grid-local corners (doubles) and world corners, vertex normals and
    // material (floats; the material as its bits), in the scene's order.
    let corners: Vec<f64> = local.iter().flat_map(|t| t.iter().flat_map(|p| p.to_array())).collect();
    let max_material = u32::from(layout.max_material());
    let tri_data: Vec<f32> = (0..attrs.triangles.len() as u32)
        .flat_map(|t| {
            let c = attrs.corners(t);
            let nrm = attrs.triangles[t as usize].map(|i| attrs.vertices[i as usize].normal);
            let m = u32::from(attrs.material(t)).min(max_material);
            let mut d = [0f32; 20];
            for k in 0..3 {
                d[3 * k..3 * k + 3].copy_from_slice(&c[k].to_array());
                d[9 + 3 * k..12 + 3 * k].copy_from_slice(&nrm[k]);
            }
            d[18] = f32::from_bits(m);
            d
        })
        .collect();
    let mut run = || -> kiln_gpubake::Result<()> {
        let params_buf = staged(compute, std::slice::from_ref(&params))?;
        let corners_buf = staged(compute, &corners)?;
        let tris_buf = staged(compute, &tri_data)?;
        compute.run(|c| {
            for b in [&params_buf, &corners_buf, &tris_buf] {
                c.copy(&b.host, &b.device, b.host.size());
            }
            Ok(())
        })?;
        // Every buffer a kernel binds must stay within the device's storage-buffer range.
        let limit = BATCH_SCRATCH.min(compute.max_buffer());
        let max_cells = (limit / (shafts as u64 * END_BYTES)).max(1) as usize;
        let per_cell_triangle = 30 * 8u64.max(4 * words as u64);
        let max_tris = BATCH_CELL_TRIANGLES.min((limit / per_cell_triangle) as usize);
        let mut rank =
            out.ranks.last().map_or(0, |&r| r as u64) + out.bits.last().map_or(0, |w| w.count_ones() as u64);
        let mut start = 0;
        while start < occupied.len() {
            // Cells up to the scratch's and the triangle lists' budgets.
            let mut end = start;
            let mut tris = 0usize;
            while end < occupied.len() && end - start < max_cells {
                let c = occupied[end];
                let len = (voxel_offsets[c + 1] - voxel_offsets[c]) as usize;
                if end > start && tris + len > max_tris {
                    break;
                }
                tris += len;
                end += 1;
            }
            let batch = &occupied[start..end];
            let prepared =
                prepare(attrs, header, local, voxel_offsets, voxel_triangles, batch, margin, layout, pnmt);
            let Prepared { mut cells, cell_tris, keys, fallbacks } = prepared;
            let cells_buf = staged(compute, &cells)?;
            let cell_tris_buf = staged(compute, &cell_tris)?;
            let keys_buf = staged(compute, &keys)?;
            let ends = compute.buffer(batch.len() as u64 * shafts as u64 * END_BYTES, Memory::Device)?;
            let bits_bytes = (batch.len() * wps * 4) as u64;
            let bits = compute.buffer(bits_bytes, Memory::Device)?;
            let bits_back = compute.buffer(bits_bytes, Memory::Readback)?;
            let tests_bytes = batch.len() as u64 * 15 * 4;
            let tests = compute.buffer(tests_bytes, Memory::Device)?;
            let tests_back = compute.buffer(tests_bytes, Memory::Readback)?;
            compute.run(|c| {
                for b in [&cells_buf, &cell_tris_buf, &keys_buf] {
                    c.copy(&b.host, &b.device, b.host.size());
                }
                c.zero(&bits, bits.size());
                c.dispatch(
                    &gpu.search,
                    &[
                        &params_buf.device,
                        &cells_buf.device,
                        &cell_tris_buf.device,
                        &keys_buf.device,
                        &corners_buf.device,
                        &tris_buf.device,
                        &ends,
                        &bits,
                        &tests,
                    ],
                    [batch.len() as u32, 15, 1],
                )?;
                c.copy(&bits, &bits_back, bits_bytes);
                c.copy(&tests, &tests_back, tests_bytes);
                c.to_host();
                Ok(())
            })?;
            let batch_bits: &[u32] = bytemuck::cast_slice(&bits_back.bytes()[..bits_bytes as usize]);
            out.tests += bytemuck::cast_slice::<u8, u32>(&tests_back.bytes()[..tests_bytes as usize])
                .iter()
                .map(|&t| t as u64)
                .sum::<u64>();
            // Ranks, and each cell's first record in the batch.
            let mut filled = 0u64;
            for (cell, words) in cells.iter_mut().zip(batch_bits.chunks_exact(wps)) {
                cell.record_base = filled as u32;
                for &w in words {
                    out.ranks.push(
                        u32::try_from(rank)
                            .map_err(|_| kiln_gpubake::Error(super::too_many().to_string()))?,
                    );
                    rank += w.count_ones() as u64;
                    filled += w.count_ones() as u64;
                }
            }
            out.bits.extend_from_slice(batch_bits);
            if pnmt && filled > 0 {
                let fallbacks_buf = staged(compute, &fallbacks)?;
                let mut cells_again = compute.buffer(cells_buf.host.size(), Memory::Upload)?;
                cells_again.write(&cells)?;
                let record_bytes = filled * 2 * words as u64 * 4;
                let records = compute.buffer(record_bytes, Memory::Device)?;
                let records_back = compute.buffer(record_bytes, Memory::Readback)?;
                compute.run(|c| {
                    c.copy(&cells_again, &cells_buf.device, cells_again.size());
                    c.copy(&fallbacks_buf.host, &fallbacks_buf.device, fallbacks_buf.host.size());
                    c.dispatch(
                        &gpu.records,
                        &[
                            &params_buf.device,
                            &cells_buf.device,
                            &fallbacks_buf.device,
                            &tris_buf.device,
                            &ends,
                            &bits,
                            &records,
                        ],
                        [batch.len() as u32, 1, 1],
                    )?;
                    c.copy(&records, &records_back, record_bytes);
                    c.to_host();
                    Ok(())
                })?;
                let recs: &[u32] = bytemuck::cast_slice(&records_back.bytes()[..record_bytes as usize]);
                out.pnmt.extend_from_slice(recs);
                out.pnmt_missing += recs
                    .par_chunks_exact(2 * words as usize)
                    .filter(|r| !layout.is_some(&r[..]) || !layout.is_some(&r[words as usize..]))
                    .count() as u64;
            }
            progress.inc(batch.len() as u64);
            start = end;
        }
        Ok(())
    };
    run().map_err(gpu_err)
}

/// One batch's cells, their triangle lists, and per cell triangle the key bounds and fallback
/// records (`triangle_pair_data`).
struct Prepared {
    cells: Vec<BakeCell>,
    cell_tris: Vec<u32>,
    keys: Vec<f64>,
    fallbacks: Vec<u32>,
}

#[allow(clippy::too_many_arguments)]
fn prepare(
    attrs: &SceneAttributes,
    header: &GridHeader,
    local: &[[DVec3; 3]],
    voxel_offsets: &[u32],
    voxel_triangles: &[u32],
    batch: &[usize],
    margin: f64,
    layout: PnmtLayout,
    pnmt: bool,
) -> Prepared {
    let parts: Vec<(Vec<f64>, Vec<u32>)> = batch
        .par_iter()
        .map_init(
            || (Vec::new(), Vec::new()),
            |scratch, &c| {
                let cc = header.cell_coords(c);
                let grid_min = DVec3::new(cc[0] as f64, cc[1] as f64, cc[2] as f64);
                let tris = &voxel_triangles[voxel_offsets[c] as usize..voxel_offsets[c + 1] as usize];
                let mut keys = Vec::with_capacity(tris.len() * 30);
                let mut fallbacks = Vec::new();
                for &t in tris {
                    let v = local[t as usize].map(|p| p - grid_min);
                    triangle_pair_data(
                        attrs,
                        layout,
                        t,
                        v,
                        margin,
                        header.cell_min(cc),
                        header.cell,
                        (&mut scratch.0, &mut scratch.1),
                        &mut keys,
                        &mut fallbacks,
                    );
                }
                if !pnmt {
                    fallbacks.clear();
                }
                (keys, fallbacks)
            },
        )
        .collect();
    let mut cells = Vec::with_capacity(batch.len());
    let mut cell_tris = Vec::new();
    for &c in batch {
        let cc = header.cell_coords(c);
        let w = header.cell_min(cc);
        let tris = &voxel_triangles[voxel_offsets[c] as usize..voxel_offsets[c + 1] as usize];
        cells.push(BakeCell {
            gx: cc[0] as f64,
            gy: cc[1] as f64,
            gz: cc[2] as f64,
            wx: w.x,
            wy: w.y,
            wz: w.z,
            cell: header.cell,
            inv_cell: 1.0 / header.cell,
            tri_first: cell_tris.len() as u32,
            tri_count: tris.len() as u32,
            ..Default::default()
        });
        cell_tris.extend_from_slice(tris);
    }
    let keys = parts.iter().flat_map(|p| p.0.iter().copied()).collect();
    let fallbacks = parts.iter().flat_map(|p| p.1.iter().copied()).collect();
    Prepared { cells, cell_tris, keys, fallbacks }
}
