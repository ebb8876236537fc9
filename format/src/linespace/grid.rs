//! The voxel grid: its header, cell addressing and a 3D-DDA (Amanatides and Woo 1987) in double
//! precision, relative to the grid origin so that scenes far from the origin keep their
//! precision.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};

/// Variant bits of [`GridHeader::variants`].
#[derive(Debug)]
pub struct Variants;

impl Variants {
    /// One bit per shaft (always present when any line space is: it indexes the others).
    pub const BINARY: u32 = 1 << 0;
    /// Exact per-shaft triangle lists.
    pub const CANDIDATES: u32 = 1 << 1;
    /// Front and back hit records of each filled shaft's midpoint ray.
    pub const PNMT: u32 = 1 << 2;
    /// Front and back radiance of each filled shaft under the static lights.
    pub const PREILLUM: u32 = 1 << 3;
    /// Every defined bit.
    pub const ALL: u32 = Self::BINARY | Self::CANDIDATES | Self::PNMT | Self::PREILLUM;
    /// What the compiler bakes by default for a lit scene (within its size budget).
    pub const DEFAULT: u32 = Self::BINARY | Self::CANDIDATES | Self::PNMT;
    /// Each variant with its name in `--shaft-variants` lists.
    pub const NAMES: [(u32, &'static str); 4] = [
        (Self::BINARY, "binary"),
        (Self::CANDIDATES, "candidates"),
        (Self::PNMT, "pnmt"),
        (Self::PREILLUM, "preillum"),
    ];

    /// A variant set as a `--shaft-variants` list (`none` for the empty set).
    pub fn list(v: u32) -> String {
        let names: Vec<&str> = Self::NAMES.iter().filter(|(bit, _)| v & bit != 0).map(|(_, n)| *n).collect();
        if names.is_empty() { "none".into() } else { names.join(",") }
    }
}

/// Header of the voxel grid and line space (section `VGRD`, one element). 96 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
#[repr(C)]
pub struct GridHeader {
    /// Minimum corner of the grid, scene units.
    pub origin: [f64; 3],
    /// Edge length of the cubic cells.
    pub cell: f64,
    /// How far voxels and shafts are widened (scene units) so that the single-precision
    /// ray–triangle test cannot find a hit outside a voxel's or shaft's stored triangles.
    pub margin: f64,
    /// Cells along x, y, z.
    pub dims: [u32; 3],
    /// Shaft resolution N (patches per face edge); 0 when there is no line space.
    pub shaft_res: u32,
    /// [`Variants`] present.
    pub variants: u32,
    /// Non-empty cells, each with a line-space slot.
    pub slots: u32,
    /// Filled shafts over all slots.
    pub filled: u64,
    /// Candidate list entries over all filled shafts.
    pub entries: u64,
    /// Largest triangle count of one cell.
    pub max_cell_triangles: u32,
    /// How PNMT records are stored: a [`crate::linespace::PnmtLayout`] code (0, the full
    /// 16-byte record, in files from before the compact layouts).
    pub pnmt_layout: u32,
    /// Zero.
    pub reserved: [u32; 2],
}

const _: () = assert!(size_of::<GridHeader>() == 96);

impl GridHeader {
    /// The layout [`Self::pnmt_layout`] names, `None` for an undefined code.
    pub fn pnmt_records(&self) -> Option<crate::linespace::PnmtLayout> {
        crate::linespace::PnmtLayout::from_code(self.pnmt_layout)
    }

    /// Number of cells.
    pub fn cell_count(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }

    /// Linear index of cell (x, y, z): x fastest.
    pub fn cell_index(&self, c: [u32; 3]) -> usize {
        (c[0] as usize) + self.dims[0] as usize * (c[1] as usize + self.dims[1] as usize * c[2] as usize)
    }

    /// Cell coordinates of a linear index.
    pub fn cell_coords(&self, i: usize) -> [u32; 3] {
        let (dx, dy) = (self.dims[0] as usize, self.dims[1] as usize);
        [(i % dx) as u32, ((i / dx) % dy) as u32, (i / (dx * dy)) as u32]
    }

    /// Minimum corner of a cell.
    pub fn cell_min(&self, c: [u32; 3]) -> DVec3 {
        DVec3::from(self.origin) + DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * self.cell
    }

    /// Maximum corner of the grid.
    pub fn grid_max(&self) -> DVec3 {
        DVec3::from(self.origin)
            + DVec3::new(self.dims[0] as f64, self.dims[1] as f64, self.dims[2] as f64) * self.cell
    }
}

/// One cell visited by a ray: its coordinates and the ray parameters where the *line* enters
/// and leaves it (not clipped to the ray's interval).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellVisit {
    /// Cell coordinates.
    pub cell: [u32; 3],
    /// Line parameter at entry.
    pub t_enter: f64,
    /// Line parameter at exit.
    pub t_exit: f64,
}

/// Iterator over the cells a ray segment passes through, in order along the ray.
#[derive(Debug, Clone)]
pub struct Dda {
    o: DVec3,
    d: DVec3,
    dims: [i64; 3],
    cell: [i64; 3],
    step: [i64; 3],
    t_next: [f64; 3],
    t: f64,
    t_end: f64,
    done: bool,
}

impl Dda {
    /// Cells of `grid` met by `origin + t·dir` for `t` in `[t0, t1]`.
    pub fn new(grid: &GridHeader, origin: Vec3, dir: Vec3, t0: f32, t1: f32) -> Dda {
        let o = (origin.as_dvec3() - DVec3::from(grid.origin)) / grid.cell;
        let d = dir.as_dvec3() / grid.cell;
        let dims = [grid.dims[0] as i64, grid.dims[1] as i64, grid.dims[2] as i64];
        let mut lo = t0 as f64;
        let mut hi = t1 as f64;
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < 0.0 || o[a] > dims[a] as f64 {
                    hi = f64::NEG_INFINITY;
                }
            } else {
                let (ta, tb) = ((0.0 - o[a]) / d[a], (dims[a] as f64 - o[a]) / d[a]);
                lo = lo.max(ta.min(tb));
                hi = hi.min(ta.max(tb));
            }
        }
        let mut dda = Dda {
            o,
            d,
            dims,
            cell: [0; 3],
            step: [0; 3],
            t_next: [f64::INFINITY; 3],
            t: lo,
            t_end: hi,
            done: !(lo <= hi),
        };
        if dda.done {
            return dda;
        }
        let p = o + d * lo;
        for a in 0..3 {
            let mut c = p[a].floor() as i64;
            // A start exactly on a cell plane while moving down belongs to the lower cell.
            if d[a] < 0.0 && p[a] == p[a].floor() {
                c -= 1;
            }
            dda.cell[a] = c.clamp(0, dims[a] - 1);
            dda.step[a] = if d[a] > 0.0 {
                1
            } else if d[a] < 0.0 {
                -1
            } else {
                0
            };
            dda.t_next[a] = dda.boundary(a);
        }
        dda
    }

    /// Line parameter of the current cell's exit plane along axis `a`, computed from the cell
    /// index (not accumulated, so long traversals do not drift).
    fn boundary(&self, a: usize) -> f64 {
        match self.step[a] {
            1 => ((self.cell[a] + 1) as f64 - self.o[a]) / self.d[a],
            -1 => (self.cell[a] as f64 - self.o[a]) / self.d[a],
            _ => f64::INFINITY,
        }
    }
}

impl Iterator for Dda {
    type Item = CellVisit;

    fn next(&mut self) -> Option<CellVisit> {
        if self.done {
            return None;
        }
        let a = if self.t_next[0] <= self.t_next[1] && self.t_next[0] <= self.t_next[2] {
            0
        } else if self.t_next[1] <= self.t_next[2] {
            1
        } else {
            2
        };
        let exit = self.t_next[a];
        let visit = CellVisit {
            cell: [self.cell[0] as u32, self.cell[1] as u32, self.cell[2] as u32],
            t_enter: self.t,
            t_exit: exit.min(self.t_end).max(self.t),
        };
        if exit >= self.t_end {
            self.done = true;
        } else {
            self.cell[a] += self.step[a];
            self.t = exit;
            self.t_next[a] = self.boundary(a);
            if self.cell[a] < 0 || self.cell[a] >= self.dims[a] {
                self.done = true;
            }
        }
        Some(visit)
    }
}
