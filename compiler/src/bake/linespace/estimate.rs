//! The line space's size, estimated before the bake: the voxel grid gives the exact sizes of the
//! grid and binary sections; a sample of non-empty cells, baked exactly (bits and candidate lists,
//! no PNMT records), gives the filled-shaft and candidate-entry rates the other sections scale with.

use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

use super::shafts::{self, HitAttributes};
use super::voxelize::Voxels;

/// Most cells baked per estimate.
pub const SAMPLE_CELLS: usize = 256;

/// Cell–triangle pairs the sample may bake whatever the scene's size: below this many in all, every
/// cell is baked (the estimate is then exact); above, the sample takes an eighth of them, so that
/// an estimate costs at most about an eighth of the bake even on coarse grids of heavy cells (the
/// bunny count at 8³: 383 cells, a 39 s PNMT bake on two threads; baking 192 of them took 12 s).
pub const SAMPLE_PAIRS: usize = 16_384;

/// Standard errors added to the sample's mean: the estimate is an upper bound at about 97.5%
/// confidence, so that a configuration chosen to fit a budget fits once baked (the per-cell
/// counts vary widely: wall cells against object cells).
pub const STANDARD_ERRORS: f64 = 2.0;

/// What the sampled cells hold.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct FillSample {
    /// Non-empty cells in all.
    pub occupied: u64,
    /// Filled shafts and candidate entries of each cell baked.
    pub cells: Vec<(u64, u64)>,
}

impl FillSample {
    /// Filled shafts and candidate entries of all non-empty cells, extrapolated: the sample's
    /// mean per cell plus `z` standard errors (with the finite-population correction: exact when
    /// every cell was baked), times the cells.
    pub fn extrapolate(&self, z: f64) -> (u64, u64) {
        let k = self.cells.len() as f64;
        if k == 0.0 {
            return (0, 0);
        }
        let total = self.occupied as f64;
        let bound = |x: &dyn Fn(&(u64, u64)) -> u64| {
            let mean = self.cells.iter().map(|c| x(c) as f64).sum::<f64>() / k;
            let var = if k > 1.0 {
                self.cells.iter().map(|c| (x(c) as f64 - mean).powi(2)).sum::<f64>() / (k - 1.0)
            } else {
                0.0
            };
            let se = (var / k * (1.0 - k / total).max(0.0)).sqrt();
            ((mean + z * se) * total).round() as u64
        };
        (bound(&|c| c.0), bound(&|c| c.1))
    }
}

/// No hit attributes: the sample bakes no PNMT or pre-illuminated records, which alone read them.
struct NoAttributes;

impl HitAttributes for NoAttributes {
    fn corners(&self, _: u32) -> [Vec3; 3] {
        [Vec3::ZERO; 3]
    }
    fn normal(&self, _: u32, _: f32, _: f32) -> Vec3 {
        Vec3::Z
    }
    fn uv(&self, _: u32, _: f32, _: f32) -> Vec2 {
        Vec2::ZERO
    }
    fn material(&self, _: u32) -> u16 {
        0
    }
}

/// Bakes up to `max_cells` non-empty cells of `voxels` (holding about [`SAMPLE_PAIRS`] or an
/// eighth of the cell–triangle pairs, whichever is more), evenly spaced in cell order, at shaft
/// resolution `n`, and counts their filled shafts and candidate entries. Deterministic.
pub fn sample(voxels: &Voxels, n: u32, max_cells: usize) -> FillSample {
    let h = &voxels.header;
    let offsets = &voxels.offsets;
    let occupied: Vec<usize> =
        (0..h.cell_count() as usize).filter(|&c| offsets[c + 1] > offsets[c]).collect();
    if occupied.is_empty() || max_cells == 0 {
        return FillSample { occupied: occupied.len() as u64, cells: Vec::new() };
    }
    let pairs = voxels.triangles.len();
    let target = (pairs / 8).max(SAMPLE_PAIRS);
    let step = occupied.len().div_ceil(max_cells).max(pairs.div_ceil(target));
    let picked: Vec<usize> = occupied.iter().copied().step_by(step).collect();
    let margin_local = h.margin / h.cell;
    let cells: Vec<(u64, u64)> = picked
        .par_iter()
        .map_init(shafts::Scratch::default, |scratch, &c| {
            let cc = h.cell_coords(c);
            let cell_min = DVec3::new(cc[0] as f64, cc[1] as f64, cc[2] as f64);
            let tris = &voxels.triangles[offsets[c] as usize..offsets[c + 1] as usize];
            let r = shafts::bake_cell(
                tris,
                &voxels.local,
                cell_min,
                h.cell_min(cc),
                h.cell,
                n,
                margin_local,
                true,
                false,
                kiln_format::linespace::PnmtLayout::Full,
                &NoAttributes,
                None,
                scratch,
            );
            let filled: u64 = r.bits.iter().map(|w| w.count_ones() as u64).sum();
            (filled, r.entries.len() as u64)
        })
        .collect();
    FillSample { occupied: occupied.len() as u64, cells }
}
