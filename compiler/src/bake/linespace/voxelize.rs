//! The voxel grid: resolution, margin, and exact conservative triangle–cell overlap (separating
//! axes, cells widened by the margin) stored as CSR lists.

use glam::DVec3;
use kiln_format::linespace::GridHeader;
use kiln_format::manifest::Bounds;
use rayon::prelude::*;

use super::geometry::Prepared;

/// Cells along the longest axis chosen by `--voxel-res auto`: the cube root of the triangle
/// count (about one triangle per cell of a cube's volume, O(T^⅔) non-empty cells on surfaces),
/// clamped to 4..=64.
pub fn auto_resolution(triangles: usize) -> u32 {
    ((triangles as f64).cbrt().round() as u32).clamp(4, 64)
}

/// How far voxels and shafts are widened: 8 single-precision ulps of the largest coordinate
/// magnitude of the grid plus its diagonal (the reach of the f32 ray–triangle test's rounding
/// for rays that start within that range), and a millionth of a cell.
pub fn margin(origin: DVec3, extent: DVec3, cell: f64) -> f64 {
    let far = origin.abs().max((origin + extent).abs()).max_element();
    (far + extent.length()) * 8.0 * f32::EPSILON as f64 + cell * 1e-6
}

/// The grid over `bounds` with `res` cubic cells along the longest axis. It covers the bounds
/// widened by four of its own margins on every side, so that every point within a margin of a
/// triangle (every point the single-precision ray–triangle test can report as a hit) lies strictly
/// inside a cell: `origin ≤ min − 4·margin` and `origin + dims·cell ≥ max + 4·margin` per axis,
/// evaluated in f64 (see [`covers`]). The margin depends on the grid it pads, so the padding is
/// grown until the grid's own margin fits (once or twice).
pub fn grid(bounds: &Bounds, res: u32) -> GridHeader {
    let lo0 = DVec3::from(bounds.min.map(f64::from));
    let hi0 = DVec3::from(bounds.max.map(f64::from));
    let mut pad = 4.0 * margin(lo0, (hi0 - lo0).max(DVec3::ZERO), (hi0 - lo0).max_element() / res as f64);
    loop {
        let g = padded_grid(lo0, hi0, pad, res);
        if covers(&g, bounds) {
            return g;
        }
        pad = pad.max(4.0 * g.margin) * (1.0 + 1e-6);
    }
}

/// Whether `g` covers `bounds` widened by four of its margins on every side (in f64).
pub fn covers(g: &GridHeader, bounds: &Bounds) -> bool {
    (0..3).all(|a| {
        let far = g.origin[a] + g.dims[a] as f64 * g.cell;
        g.origin[a] <= bounds.min[a] as f64 - 4.0 * g.margin && far >= bounds.max[a] as f64 + 4.0 * g.margin
    })
}

fn padded_grid(lo0: DVec3, hi0: DVec3, pad: f64, res: u32) -> GridHeader {
    let (lo, hi) = (lo0 - pad, hi0 + pad);
    let extent = hi - lo;
    let mut cell = (extent.max_element() / res as f64).max(f64::MIN_POSITIVE);
    // `res` cells must span the longest axis although the division rounds.
    while res as f64 * cell < extent.max_element() {
        cell = cell.next_up();
    }
    let dims = [0, 1, 2].map(|a| ((extent[a] / cell).ceil() as u32).clamp(1, res));
    // Centre the grid on the bounds so that both sides have the same slack.
    let size = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * cell;
    let origin = lo - (size - extent) * 0.5;
    GridHeader {
        origin: origin.to_array(),
        cell,
        margin: margin(origin, size, cell),
        dims,
        ..Default::default()
    }
}

/// Triangle corners in grid-local coordinates (cells are unit cubes, the grid starts at 0).
pub fn local_triangles(grid: &GridHeader, corners: &[[[f32; 3]; 3]]) -> Vec<[DVec3; 3]> {
    let o = DVec3::from(grid.origin);
    corners.iter().map(|c| c.map(|p| (DVec3::from(p.map(f64::from)) - o) / grid.cell)).collect()
}

/// CSR lists of the triangles meeting each (widened) cell: (offsets, triangles), triangles
/// ascending within a cell. Deterministic for any thread count.
pub fn voxelize(grid: &GridHeader, local: &[[DVec3; 3]]) -> (Vec<u32>, Vec<u32>) {
    let m = grid.margin / grid.cell;
    let dims = grid.dims.map(|d| d as i64);
    let pairs: Vec<Vec<(u32, u32)>> = local
        .par_chunks(4096)
        .enumerate()
        .map(|(chunk, tris)| {
            let mut out = Vec::new();
            for (k, v) in tris.iter().enumerate() {
                let t = (chunk * 4096 + k) as u32;
                let prep = Prepared::new(*v);
                let lo = v[0].min(v[1]).min(v[2]) - m;
                let hi = v[0].max(v[1]).max(v[2]) + m;
                let range = |a: usize| {
                    (
                        (lo[a].floor() as i64).clamp(0, dims[a] - 1),
                        (hi[a].floor() as i64).clamp(0, dims[a] - 1),
                    )
                };
                let ((x0, x1), (y0, y1), (z0, z1)) = (range(0), range(1), range(2));
                for z in z0..=z1 {
                    for y in y0..=y1 {
                        for x in x0..=x1 {
                            let centre = DVec3::new(x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5);
                            if prep.overlaps_box(centre, DVec3::splat(0.5 + m)) {
                                out.push((grid.cell_index([x as u32, y as u32, z as u32]) as u32, t));
                            }
                        }
                    }
                }
            }
            out
        })
        .collect();
    let cells = grid.cell_count() as usize;
    let mut offsets = vec![0u32; cells + 1];
    for &(c, _) in pairs.iter().flatten() {
        offsets[c as usize + 1] += 1;
    }
    for i in 0..cells {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut tris = vec![0u32; offsets[cells] as usize];
    // Chunks are in triangle order, so each cell's list comes out ascending.
    for &(c, t) in pairs.iter().flatten() {
        tris[fill[c as usize] as usize] = t;
        fill[c as usize] += 1;
    }
    (offsets, tris)
}

/// A voxelized scene: the grid, the triangles in grid-local coordinates and each cell's
/// triangle list, in one triangle order.
#[derive(Debug, Clone)]
pub struct Voxels {
    /// The grid (`max_cell_triangles` set; the line-space fields left at zero).
    pub header: GridHeader,
    /// Triangle corners in grid-local coordinates.
    pub local: Vec<[DVec3; 3]>,
    /// Cell triangle list offsets (CSR).
    pub offsets: Vec<u32>,
    /// Cell triangle lists, ascending within a cell.
    pub triangles: Vec<u32>,
}

impl Voxels {
    /// Voxelizes the triangles with world-space `corners` over `bounds` at `res` cells along the
    /// longest axis.
    pub fn new(bounds: &Bounds, res: u32, corners: &[[[f32; 3]; 3]]) -> Voxels {
        let mut header = grid(bounds, res);
        let local = local_triangles(&header, corners);
        let (offsets, triangles) = voxelize(&header, &local);
        header.max_cell_triangles = offsets.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0);
        Voxels { header, local, offsets, triangles }
    }

    /// Cells holding at least one triangle.
    pub fn occupied_cells(&self) -> usize {
        self.offsets.windows(2).filter(|w| w[1] > w[0]).count()
    }

    /// The same voxelization with the triangles renumbered: `order[i]` is the triangle stored at
    /// position `i`. Equal to voxelizing the reordered triangles, since a triangle's cells depend
    /// on its corners alone.
    pub fn reordered(&self, order: &[u32]) -> Voxels {
        let mut position = vec![0u32; order.len()];
        for (i, &t) in order.iter().enumerate() {
            position[t as usize] = i as u32;
        }
        let mut triangles: Vec<u32> = self.triangles.iter().map(|&t| position[t as usize]).collect();
        for w in self.offsets.windows(2) {
            triangles[w[0] as usize..w[1] as usize].sort_unstable();
        }
        Voxels {
            header: self.header,
            local: order.iter().map(|&t| self.local[t as usize]).collect(),
            offsets: self.offsets.clone(),
            triangles,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid covers the bounds widened by four of its own margins (FORMAT.md, `VGRD`), over
    /// boxes near and far from the origin, flat, tiny and at every resolution class.
    #[test]
    fn grid_covers_bounds_widened_by_four_margins() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut old_short = 0;
        for i in 0..20_000 {
            let scale = 10f64.powf(next() * 8.0 - 3.0);
            let offset = 10f64.powf(next() * 7.0 - 1.0) * if next() < 0.5 { -1.0 } else { 1.0 };
            let min = [0; 3].map(|_| (offset + (next() - 0.5) * scale) as f32);
            let max = min.map(|m| m + if next() < 0.1 { 0.0 } else { (next() * scale) as f32 });
            let bounds = Bounds { min, max };
            let res = [1, 2, 3, 4, 7, 16, 64, 1024][i % 8];
            let g = grid(&bounds, res);
            assert!(covers(&g, &bounds), "{bounds:?} at {res}: {g:?}");
            assert!(g.dims.iter().all(|&d| (1..=res).contains(&d)) && g.dims.contains(&res));
            // The old padding (four margins of the unpadded bounds) fell short on some of these.
            let (lo0, hi0) = (DVec3::from(min.map(f64::from)), DVec3::from(max.map(f64::from)));
            let pad = 4.0 * margin(lo0, hi0 - lo0, (hi0 - lo0).max_element() / res as f64);
            old_short += !covers(&padded_grid(lo0, hi0, pad, res), &bounds) as u32;
        }
        assert!(old_short > 0, "the test no longer exercises the shortfall");
    }
}
