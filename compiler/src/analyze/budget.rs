//! The line space's configuration under a size budget: voxel resolution, shaft resolution N and
//! (when not given) variants, chosen so that the estimated size of the grid and line-space
//! sections fits.
//!
//! **The estimate.** The voxel grid at a candidate resolution (cached, reused by the bake when
//! chosen) gives the grid sections and the binary variant exactly (`VOXO`, `VOXT`, `LSLT`, `LSBN`,
//! `LSRK` depend on the non-empty cells alone). The filled shafts and candidate entries, which the
//! candidate, PNMT and preillum sections scale with, are extrapolated from
//! [`estimate::SAMPLE_CELLS`] non-empty cells baked exactly.
//!
//! **The search.** Size grows as (non-empty cells) × 15·N⁴: about res² · N⁴ on surfaces. N sets
//! the shafts' angular resolution (a shaft spans about 1/N of a cell in each endpoint), which no
//! voxel resolution buys back, while the cells' size can shrink again by raising res; so N stays
//! as requested (4 by default, the thesis used 5) and the voxel resolution is lowered first, to
//! [`RES_FLOOR`] cells, then N, to 1. Each step to a lower resolution is predicted from the last
//! estimate by a cube root of the overshoot (conservative for the res² growth of surfaces, so it
//! never skips a fitting resolution of such a scene), at least one cell.
//!
//! **Variants**, when the plan chooses them: at the requested resolutions, all three, else binary
//! + PNMT; if neither fits, binary + PNMT at lower resolutions, then binary alone. Candidates go
//!   first because coarser cells shrink them least (their entries per filled shaft grow with the
//!   triangles per cell: on the teapot-count box at N = 5, 32³ → 8³ shrinks PNMT 17×, candidates
//!   7×, `benches/linespace.rs` rows 3 and 4), and the plan dropped them first before budgets.
//!
//! Explicit `--voxel-res` and `--shaft-res` are not searched: with both given, a budget they
//! exceed is a usage error naming them.

use serde::Serialize;

use kiln_format::linespace::{MAX_CANDIDATE_CELL_TRIANGLES, PnmtLayout, Variants, words_per_slot};

use crate::analyze::geometry::SceneGeometry;
use crate::bake::linespace::estimate;
use crate::settings::variants_name;

/// The default budget is this many times the geometry's bytes ([`default_budget_mib`]): the
/// line space then at most doubles what a file needs to render, so a default file stays small
/// enough to ship (issue: `pica_pica`'s 8 MB of glTF became 319 MiB of line space at 384 MiB).
pub const DEFAULT_BUDGET_PER_GEOMETRY: u64 = 2;

/// The default budget's floor, MiB: a small scene still gets a line space at the thesis's
/// resolutions (the Cornell box's, all variants at 4³ cells, N = 4, is 6.9 MiB).
pub const DEFAULT_BUDGET_MIN_MIB: u32 = 8;

/// The default budget's ceiling, MiB (the fixed default before budgets scaled with the scene).
pub const DEFAULT_BUDGET_MAX_MIB: u32 = 384;

/// The default line-space budget for a scene whose geometry sections (`VERT`, `UVS0`, `COL0`,
/// `TRIS`, `TMAT`) take `geometry_bytes`: [`DEFAULT_BUDGET_PER_GEOMETRY`] times them, rounded up
/// to whole MiB, within [`DEFAULT_BUDGET_MIN_MIB`]..=[`DEFAULT_BUDGET_MAX_MIB`].
pub fn default_budget_mib(geometry_bytes: u64) -> u32 {
    let scaled = (geometry_bytes.saturating_mul(DEFAULT_BUDGET_PER_GEOMETRY)).div_ceil(1 << 20);
    scaled.clamp(DEFAULT_BUDGET_MIN_MIB as u64, DEFAULT_BUDGET_MAX_MIB as u64) as u32
}

/// Lowest voxel resolution the search goes to before it lowers N (auto's lower clamp).
pub const RES_FLOOR: u32 = 4;

/// Bytes per part of the grid and line space.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct PartBytes {
    /// `VGRD`, `VOXO`, `VOXT`.
    pub grid: u64,
    /// `LSLT`, `LSBN`, `LSRK`.
    pub binary: u64,
    /// `LSCO`, `LSCE`.
    pub candidates: u64,
    /// `LSPN`.
    pub pnmt: u64,
    /// `LSPI`.
    pub preillum: u64,
}

impl PartBytes {
    /// Bytes of the grid and the sections of `variants` (binary always).
    pub fn total(&self, variants: u32) -> u64 {
        let has = |bit| variants & bit != 0;
        self.grid
            + self.binary
            + if has(Variants::CANDIDATES) { self.candidates } else { 0 }
            + if has(Variants::PNMT) { self.pnmt } else { 0 }
            + if has(Variants::PREILLUM) { self.preillum } else { 0 }
    }
}

/// The estimated line space at one (voxel resolution, N).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    /// Cells along the longest axis.
    pub voxel_res: u32,
    /// Cells per axis.
    pub dims: [u32; 3],
    /// Edge of a cell, scene units.
    pub cell: f64,
    /// Non-empty cells.
    pub slots: u64,
    /// Triangles of the fullest cell.
    pub max_cell_triangles: u32,
    /// Shaft resolution N.
    pub shaft_res: u32,
    /// Filled shafts (extrapolated).
    pub filled: u64,
    /// Candidate entries (extrapolated).
    pub entries: u64,
    /// Bytes per part.
    pub bytes: PartBytes,
}

impl Estimate {
    /// Estimates the line space of `geometry` at `res` cells and shaft resolution `n`: an upper
    /// bound at [`estimate::STANDARD_ERRORS`].
    pub fn new(geometry: &SceneGeometry, res: u32, n: u32) -> Estimate {
        Estimate::with_errors(geometry, res, n, estimate::STANDARD_ERRORS)
    }

    /// [`Estimate::new`] with `z` standard errors added to the sampled rates (0: the central
    /// estimate).
    pub fn with_errors(geometry: &SceneGeometry, res: u32, n: u32, z: f64) -> Estimate {
        let voxels = geometry.trial_voxels(res);
        let h = &voxels.header;
        let cells = h.cell_count();
        let slots = voxels.occupied_cells() as u64;
        let (filled, entries) = estimate::sample(&voxels, n, estimate::SAMPLE_CELLS).extrapolate(z);
        let words = slots * words_per_slot(n) as u64;
        Estimate {
            voxel_res: res,
            dims: h.dims,
            cell: h.cell,
            slots,
            max_cell_triangles: h.max_cell_triangles,
            shaft_res: n,
            filled,
            entries,
            bytes: PartBytes {
                grid: 96 + 4 * (cells + 1) + 4 * voxels.triangles.len() as u64,
                binary: 4 * cells + 8 * words,
                candidates: 4 * (filled + 1) + 4 * entries,
                // Full records: see [`Estimate::with_pnmt_layout`].
                pnmt: 32 * filled,
                preillum: 16 * filled,
            },
        }
    }

    /// The estimate with PNMT records stored in `layout` (estimates are made for full ones).
    pub fn with_pnmt_layout(mut self, layout: PnmtLayout) -> Estimate {
        self.bytes.pnmt = self.filled * 2 * 4 * layout.words() as u64;
        self
    }

    /// Patch edge in scene units (a cell's edge over N): the spatial resolution of a shaft's ends.
    pub fn patch(&self) -> f64 {
        self.cell / self.shaft_res as f64
    }
}

/// What the plan asks of the search.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Request {
    /// Starting voxel resolution, and whether it was given (then it is not searched).
    pub voxel_res: (u32, bool),
    /// Starting N, and whether it was given.
    pub shaft_res: (u32, bool),
    /// Variants given (`None`: the plan chooses).
    pub variants: Option<u32>,
    /// Budget in MiB, and whether it was given.
    pub budget_mib: (u32, bool),
    /// How PNMT records will be stored (their bytes per filled shaft).
    pub pnmt_layout: PnmtLayout,
}

/// The configuration chosen.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Choice {
    /// Variants (binary included).
    pub variants: u32,
    /// The estimate of the chosen (voxel resolution, N).
    pub estimate: Estimate,
    /// Estimated bytes of the grid and the chosen variants.
    pub bytes: u64,
    /// Budget, bytes (`None`: no budget applied).
    pub budget: Option<u64>,
    /// Why this configuration, in words.
    pub why: String,
}

fn mib(b: u64) -> String {
    format!("{:.1} MiB", b as f64 / (1 << 20) as f64)
}

/// Chooses the configuration for `geometry`, or an error message (a usage error: the budget, or
/// the resolutions given, cannot be met) saying the smallest size possible.
pub fn choose(geometry: &SceneGeometry, req: Request) -> Result<Choice, String> {
    let (res0, res_fixed) = req.voxel_res;
    let (n0, n_fixed) = req.shaft_res;
    let (budget_mib, budget_given) = req.budget_mib;
    let budget = (budget_mib as u64) << 20;
    let mut memo: Vec<Estimate> = Vec::new();
    let mut at = |res: u32, n: u32| -> Estimate {
        if let Some(e) = memo.iter().find(|e| e.voxel_res == res && e.shaft_res == n) {
            return *e;
        }
        let e = Estimate::new(geometry, res, n).with_pnmt_layout(req.pnmt_layout);
        memo.push(e);
        e
    };
    let done = |variants: u32, e: Estimate, why: String| Choice {
        variants,
        estimate: e,
        bytes: e.bytes.total(variants),
        budget: Some(budget),
        why,
    };
    // Explicit variants without an explicit budget: as requested, unbudgeted (as before budgets).
    if let Some(v) = req.variants
        && !budget_given
    {
        let e = at(res0, n0);
        return Ok(Choice { budget: None, ..done(v | Variants::BINARY, e, "requested".into()) });
    }
    let start = at(res0, n0);
    let full_ok = start.max_cell_triangles <= MAX_CANDIDATE_CELL_TRIANGLES;
    let sets: Vec<u32> = match req.variants {
        Some(v) => vec![v | Variants::BINARY],
        None => {
            let all = Variants::BINARY | Variants::CANDIDATES | Variants::PNMT;
            if full_ok && start.bytes.total(all) <= budget {
                return Ok(done(all, start, format!("all variants fit the {budget_mib} MiB budget")));
            }
            vec![Variants::BINARY | Variants::PNMT, Variants::BINARY]
        }
    };
    let dropped = |v: u32| match (req.variants, v & Variants::PNMT != 0) {
        (Some(_), _) => String::new(),
        (None, true) if !full_ok => format!(
            "; candidates skipped: a cell holds {} triangles, over the {MAX_CANDIDATE_CELL_TRIANGLES} they address",
            start.max_cell_triangles
        ),
        (None, true) => "; candidates skipped first (coarser cells shrink them least)".into(),
        (None, false) => "; PNMT and candidates skipped: binary + PNMT fits at no resolution".into(),
    };
    let mut smallest = start;
    let mut smallest_set = *sets.last().unwrap_or(&Variants::BINARY);
    for &v in &sets {
        let (mut res, mut n) = (res0, n0);
        loop {
            let e = at(res, n);
            if e.bytes.total(v) < smallest.bytes.total(smallest_set) {
                (smallest, smallest_set) = (e, v);
            }
            if e.bytes.total(v) <= budget {
                let how = if (res, n) == (res0, n0) {
                    format!("fits the {budget_mib} MiB budget")
                } else {
                    format!(
                        "lowered from {res0} cells, N = {n0} to fit the {budget_mib} MiB budget (voxel resolution first, then N)"
                    )
                };
                return Ok(done(v, e, format!("{how}{}", dropped(v))));
            }
            // The next configuration: a lower voxel resolution, else a lower N.
            let over = e.bytes.total(v) as f64 / budget as f64;
            if !res_fixed && res > RES_FLOOR.min(res0) {
                let predicted = (res as f64 / over.cbrt()).floor() as u32;
                res = predicted.min(res - 1).max(RES_FLOOR.min(res0));
            } else if !n_fixed && n > 1 {
                n -= 1;
            } else {
                break;
            }
        }
    }
    let what =
        format!("{} cells, N = {}, {}", smallest.voxel_res, smallest.shaft_res, variants_name(smallest_set));
    Err(match (res_fixed, n_fixed) {
        (true, true) => format!(
            "--voxel-res {res0} and --shaft-res {n0} need about {} for the line space ({}), over the {budget_mib} MiB --line-space-budget; lower them, leave one to the budget, or raise it",
            mib(smallest.bytes.total(smallest_set)),
            variants_name(smallest_set)
        ),
        _ => format!(
            "the line space fits no {budget_mib} MiB --line-space-budget: the smallest configuration ({what}) needs about {}; raise the budget{}, or use --shaft-variants none",
            mib(smallest.bytes.total(smallest_set)),
            if res_fixed || n_fixed { ", leave --voxel-res/--shaft-res to it" } else { "" }
        ),
    })
}
