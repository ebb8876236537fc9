//! The voxel grid and the line space (Keul, Müller and Lemke 2016; seed 004): sections, their
//! validation, and the CPU queries that every accelerated variant is measured against.
//!
//! Per non-empty voxel, each of the 6 faces is split into N × N patches, and every unordered
//! pair of patches on different faces bounds a *shaft* (the convex hull of the two patches):
//! 15 N⁴ shafts per voxel. Three variants can be stored:
//! - **binary**: one bit per shaft, set when a triangle meets the (widened) shaft;
//! - **candidates**: the complete list of triangles meeting each filled shaft, sorted so that a
//!   ray from either end can stop early, which makes closest-hit queries exact;
//! - **PNMT**: position, normal, material and texture coordinates of the front and back hit of
//!   each filled shaft's midpoint ray: an approximate hit without any triangle test.

pub mod glsl;
mod grid;
pub mod index;
mod pnmt;
mod query;

pub use grid::{CellVisit, Dda, GridHeader, Variants};
pub use pnmt::{
    NO_RECORD, NO_RECORD_COMPACT, PnmtHit, PnmtLayout, PnmtRecord, RecordWords, oct_decode, oct_encode,
};
pub use query::{PnmtQueryHit, ShaftLookup};

use crate::error::{FormatError, Result};
use crate::read::KilnFile;
use crate::sections::{
    CANDIDATE_OFFSETS, CANDIDATES, GRID, PNMT, PREILLUM, SHAFT_BITS, SHAFT_RANKS, SHAFT_SLOTS, VOXEL_OFFSETS,
    VOXEL_TRIANGLES,
};
use index::{MAX_SHAFT_RES, shafts_per_voxel};

/// The sections that follow the `VGRD` header: the voxel grid's cell lists, then the line
/// space's variants, in the order the player lays them out for its queries.
pub const SECTIONS: [crate::table::SectionKind; 9] = [
    VOXEL_OFFSETS,
    VOXEL_TRIANGLES,
    SHAFT_SLOTS,
    SHAFT_BITS,
    SHAFT_RANKS,
    CANDIDATE_OFFSETS,
    CANDIDATES,
    PNMT,
    PREILLUM,
];

/// Slot value of an empty cell.
pub const NO_SLOT: u32 = u32::MAX;

/// Largest triangle count of a cell with candidate lists (entries hold 16-bit local indices).
pub const MAX_CANDIDATE_CELL_TRIANGLES: u32 = 1 << 16;

/// A candidate-list entry: cell-local triangle number in bits 0..16, the quantised minimum of the
/// triangle's shaft key in bits 16..24, the running maximum of the key over this and all earlier
/// entries in bits 24..32. Keys map the shaft's key range [lo, lo + 2] to 0..255, rounded outwards.
pub mod entry {
    /// Cell-local triangle number.
    pub fn local(e: u32) -> u32 {
        e & 0xffff
    }
    /// Lower bound of the triangle's key, quantised.
    pub fn key_min(e: u32) -> u32 {
        (e >> 16) & 0xff
    }
    /// Upper bound of the keys of this and all earlier entries, quantised.
    pub fn prefix_key_max(e: u32) -> u32 {
        e >> 24
    }
    /// Packs an entry.
    pub fn pack(local: u32, key_min: u32, prefix_key_max: u32) -> u32 {
        local | key_min << 16 | prefix_key_max << 24
    }
}

/// Words of `LSBN` per slot at shaft resolution `n`.
pub fn words_per_slot(n: u32) -> usize {
    shafts_per_voxel(n).div_ceil(32) as usize
}

/// A validated view of a file's voxel grid and line space.
#[derive(Debug, Clone, Copy)]
pub struct LineSpace<'a> {
    /// Header.
    pub header: GridHeader,
    /// CSR offsets of cell triangle lists.
    pub voxel_offsets: &'a [u32],
    /// Cell triangle lists.
    pub voxel_triangles: &'a [u32],
    /// Slot per cell (empty when there is no line space).
    pub slots: &'a [u32],
    /// Shaft bits.
    pub bits: &'a [u32],
    /// Filled shafts before each bit word.
    pub ranks: &'a [u32],
    /// CSR offsets of candidate lists (empty without candidates).
    pub candidate_offsets: &'a [u32],
    /// Candidate entries.
    pub candidates: &'a [u32],
    /// PNMT records, 2 per filled shaft, [`Self::pnmt_layout`]`.words()` words each (empty
    /// without PNMT).
    pub pnmt: &'a [u32],
    /// How the PNMT records are stored.
    pub pnmt_layout: PnmtLayout,
    /// Pre-illuminated radiance per filled shaft: front RGB, 0, back RGB, 0 as binary16
    /// (empty without the variant).
    pub preillum: &'a [[u16; 8]],
    /// Words per slot.
    pub words_per_slot: usize,
}

fn bad(msg: String) -> FormatError {
    FormatError::invalid(format!("voxel grid: {msg}"))
}

impl<'a> LineSpace<'a> {
    /// Reads and validates the grid sections of `file`, `None` if it has none. `triangles` and
    /// `materials` are the scene's counts.
    pub fn new(file: &'a KilnFile, triangles: usize, materials: usize) -> Result<Option<LineSpace<'a>>> {
        let Some(header) = file.pod::<GridHeader>(GRID, 0)? else {
            for k in SECTIONS {
                if file.find(k, 0).is_some() {
                    return Err(bad(format!("section {k} without a VGRD header")));
                }
            }
            return Ok(None);
        };
        let [h] = header else {
            return Err(bad(format!("VGRD holds {} headers, must hold 1", header.len())));
        };
        let h = *h;
        let get = |k| -> Result<&'a [u32]> { Ok(file.pod::<u32>(k, 0)?.unwrap_or(&[])) };
        let ls = LineSpace {
            header: h,
            voxel_offsets: get(VOXEL_OFFSETS)?,
            voxel_triangles: get(VOXEL_TRIANGLES)?,
            slots: get(SHAFT_SLOTS)?,
            bits: get(SHAFT_BITS)?,
            ranks: get(SHAFT_RANKS)?,
            candidate_offsets: get(CANDIDATE_OFFSETS)?,
            candidates: get(CANDIDATES)?,
            pnmt: get(PNMT)?,
            pnmt_layout: h
                .pnmt_records()
                .ok_or_else(|| bad(format!("PNMT layout {} is not defined", h.pnmt_layout)))?,
            preillum: file.pod::<[u16; 8]>(PREILLUM, 0)?.unwrap_or(&[]),
            words_per_slot: if h.shaft_res == 0 { 0 } else { words_per_slot(h.shaft_res.min(MAX_SHAFT_RES)) },
        };
        // Version 1 of each (format 1.2 and before) knows only the full 16-byte records.
        let version = |k| file.find(k, 0).map_or(2, |s| s.entry.version);
        if (version(GRID) == 1 || version(PNMT) == 1) && ls.pnmt_layout != PnmtLayout::Full {
            return Err(bad(format!(
                "PNMT layout {} in a version-1 VGRD or LSPN, which hold full records only",
                ls.pnmt_layout.name()
            )));
        }
        ls.check(triangles, materials)?;
        Ok(Some(ls))
    }

    fn check(&self, triangles: usize, materials: usize) -> Result<()> {
        let h = &self.header;
        let finite = h.origin.iter().chain([&h.cell, &h.margin]).all(|v| v.is_finite());
        if !finite || !(h.cell > 0.0) || !(h.margin >= 0.0) || h.dims.contains(&0) || h.reserved != [0; 2] {
            return Err(bad(format!("header is invalid: {h:?}")));
        }
        let cells = h.cell_count();
        if cells > (1 << 31) || self.voxel_offsets.len() as u64 != cells + 1 {
            return Err(bad(format!("{} cell offsets for {cells} cells", self.voxel_offsets.len())));
        }
        if self.voxel_offsets[0] != 0 || self.voxel_offsets.windows(2).any(|w| w[0] > w[1]) {
            return Err(bad("cell offsets do not start at 0 and increase".into()));
        }
        if *self.voxel_offsets.last().unwrap_or(&0) as usize != self.voxel_triangles.len() {
            return Err(bad("cell offsets do not end at the triangle list's length".into()));
        }
        let mut max_tris = 0u32;
        let mut nonempty = 0u32;
        for c in 0..cells as usize {
            let list = self.cell_triangles(c);
            max_tris = max_tris.max(list.len() as u32);
            nonempty += !list.is_empty() as u32;
            if list.iter().any(|&t| t as usize >= triangles) || list.windows(2).any(|w| w[0] >= w[1]) {
                return Err(bad(format!("cell {c}: triangle numbers out of range or not ascending")));
            }
        }
        if max_tris != h.max_cell_triangles {
            return Err(bad(format!(
                "header says {} triangles in the fullest cell, found {max_tris}",
                h.max_cell_triangles
            )));
        }
        if h.variants == 0 {
            let extra = [self.slots, self.bits, self.ranks, self.candidate_offsets, self.candidates]
                .iter()
                .any(|s| !s.is_empty());
            if h.shaft_res != 0
                || h.slots != 0
                || h.filled != 0
                || h.entries != 0
                || extra
                || !self.pnmt.is_empty()
            {
                return Err(bad("line-space data without line-space variants in the header".into()));
            }
            return Ok(());
        }
        if h.variants & !Variants::ALL != 0 || h.variants & Variants::BINARY == 0 {
            return Err(bad(format!(
                "variant bits {:#x} are not a defined set including binary",
                h.variants
            )));
        }
        if !(1..=MAX_SHAFT_RES).contains(&h.shaft_res) {
            return Err(bad(format!("shaft resolution {} is outside 1..=8", h.shaft_res)));
        }
        // Slots are numbered in cell order over non-empty cells.
        if self.slots.len() as u64 != cells || h.slots != nonempty {
            return Err(bad(format!(
                "{} slots for {cells} cells ({nonempty} non-empty, header says {})",
                self.slots.len(),
                h.slots
            )));
        }
        let mut next = 0u32;
        for (c, &s) in self.slots.iter().enumerate() {
            let expected = if self.cell_triangles(c).is_empty() { NO_SLOT } else { next };
            if s != expected {
                return Err(bad(format!("cell {c} has slot {s}, expected {expected}")));
            }
            next += (s != NO_SLOT) as u32;
        }
        let wps = self.words_per_slot;
        if self.bits.len() != wps * h.slots as usize || self.ranks.len() != self.bits.len() {
            return Err(bad(format!(
                "{} bit words and {} rank words for {} slots of {wps} words",
                self.bits.len(),
                self.ranks.len(),
                h.slots
            )));
        }
        let tail = shafts_per_voxel(h.shaft_res) as usize % 32;
        let mut rank = 0u64;
        for (i, (&w, &r)) in self.bits.iter().zip(self.ranks).enumerate() {
            if tail != 0 && i % wps == wps - 1 && w >> tail != 0 {
                return Err(bad(format!("bit word {i} has bits set beyond the last shaft")));
            }
            if r as u64 != rank {
                return Err(bad(format!("rank word {i} is {r}, the bits before it count {rank}")));
            }
            rank += w.count_ones() as u64;
        }
        if rank != h.filled {
            return Err(bad(format!("{rank} filled shafts, header says {}", h.filled)));
        }
        let has = |v| h.variants & v != 0;
        if has(Variants::CANDIDATES) {
            if h.max_cell_triangles > MAX_CANDIDATE_CELL_TRIANGLES {
                return Err(bad("a cell has more triangles than candidate entries can address".into()));
            }
            let offs = self.candidate_offsets;
            if offs.len() as u64 != h.filled + 1 || offs[0] != 0 || offs.windows(2).any(|w| w[0] > w[1]) {
                return Err(bad(format!(
                    "{} candidate offsets for {} filled shafts, or not increasing",
                    offs.len(),
                    h.filled
                )));
            }
            if *offs.last().unwrap_or(&0) as u64 != h.entries || self.candidates.len() as u64 != h.entries {
                return Err(bad(format!(
                    "{} candidate entries, header says {}",
                    self.candidates.len(),
                    h.entries
                )));
            }
            for (c, &slot) in self.slots.iter().enumerate() {
                if slot == NO_SLOT {
                    continue;
                }
                let n = self.cell_triangles(c).len() as u32;
                let words = &self.bits[slot as usize * wps..(slot as usize + 1) * wps];
                let first = self.ranks[slot as usize * wps] as usize;
                let count: usize = words.iter().map(|w| w.count_ones() as usize).sum();
                let (a, b) = (offs[first] as usize, offs[first + count] as usize);
                if let Some(e) = self.candidates[a..b].iter().find(|&&e| entry::local(e) >= n) {
                    return Err(bad(format!(
                        "cell {c}: candidate entry {e:#x} names a triangle beyond its {n}"
                    )));
                }
            }
        } else if !self.candidate_offsets.is_empty() || !self.candidates.is_empty() || h.entries != 0 {
            return Err(bad("candidate lists present but not in the header's variants".into()));
        }
        if has(Variants::PNMT) {
            let words = self.pnmt_layout.words();
            if self.pnmt.len() as u64 != 2 * h.filled * words as u64 {
                return Err(bad(format!(
                    "{} words of {} PNMT records for {} filled shafts",
                    self.pnmt.len(),
                    self.pnmt_layout.name(),
                    h.filled
                )));
            }
            if let Some(m) = self
                .pnmt
                .chunks_exact(words)
                .map(|r| self.pnmt_layout.material(r))
                .find(|&m| m != NO_RECORD && m as usize >= materials)
            {
                return Err(bad(format!("PNMT record names material {m} of {materials}")));
            }
        } else if !self.pnmt.is_empty() {
            return Err(bad("PNMT records present but not in the header's variants".into()));
        }
        if has(Variants::PREILLUM) {
            if self.preillum.len() as u64 != h.filled {
                return Err(bad(format!(
                    "{} pre-illuminated records for {} filled shafts",
                    self.preillum.len(),
                    h.filled
                )));
            }
            // binary16 exponent all ones: infinity or NaN, which no radiance may be.
            if self.preillum.iter().flatten().any(|&x| x & 0x7c00 == 0x7c00) {
                return Err(bad("a pre-illuminated radiance is infinite or NaN".into()));
            }
        } else if !self.preillum.is_empty() {
            return Err(bad("pre-illuminated records present but not in the header's variants".into()));
        }
        Ok(())
    }

    /// Checks the grid against the scene it was baked for (FORMAT.md's "musts" that need the
    /// geometry): it covers `bounds` widened by four of its margins on every side (in f64), and
    /// every triangle a cell lists overlaps that cell widened by its margin (its box against the
    /// cell's). `vertices` and `triangles` are the scene's (indices checked by the scene view).
    pub fn check_against(
        &self,
        bounds: &crate::manifest::Bounds,
        vertices: &[crate::sections::Vertex],
        triangles: &[[u32; 3]],
    ) -> Result<()> {
        let h = &self.header;
        let m = h.margin;
        for a in 0..3 {
            let far = h.origin[a] + h.dims[a] as f64 * h.cell;
            if h.origin[a] > bounds.min[a] as f64 - 4.0 * m || far < bounds.max[a] as f64 + 4.0 * m {
                return Err(bad(format!(
                    "axis {a}: cells {}..{far} do not cover the scene's {}..{} with four margins of {m}",
                    h.origin[a], bounds.min[a], bounds.max[a]
                )));
            }
        }
        let (dx, dy) = (h.dims[0] as usize, h.dims[1] as usize);
        for c in 0..self.voxel_offsets.len().saturating_sub(1) {
            let at = [c % dx, c / dx % dy, c / (dx * dy)];
            let lo: [f64; 3] = std::array::from_fn(|a| h.origin[a] + at[a] as f64 * h.cell - m);
            let hi: [f64; 3] = std::array::from_fn(|a| lo[a] + h.cell + 2.0 * m);
            for &t in self.cell_triangles(c) {
                let Some(corners) = triangles.get(t as usize) else { continue };
                let p = corners.map(|v| vertices.get(v as usize).map_or([f32::NAN; 3], |v| v.position));
                let apart = (0..3).any(|a| {
                    let (tlo, thi) = p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), q| {
                        (l.min(q[a] as f64), u.max(q[a] as f64))
                    });
                    thi < lo[a] || tlo > hi[a]
                });
                if apart {
                    return Err(bad(format!("cell {c} {at:?} lists triangle {t}, which lies outside it")));
                }
            }
        }
        Ok(())
    }

    /// Triangles of cell `c` (linear index).
    pub fn cell_triangles(&self, c: usize) -> &'a [u32] {
        &self.voxel_triangles[self.voxel_offsets[c] as usize..self.voxel_offsets[c + 1] as usize]
    }

    /// Whether the file holds `variant`.
    pub fn has(&self, variant: u32) -> bool {
        self.header.variants & variant != 0
    }

    /// Filled-shaft rank of (slot, shaft), `None` if the shaft is empty.
    pub fn rank(&self, slot: u32, shaft: u32) -> Option<usize> {
        let w = slot as usize * self.words_per_slot + (shaft / 32) as usize;
        let bit = 1u32 << (shaft % 32);
        let word = self.bits[w];
        (word & bit != 0).then(|| self.ranks[w] as usize + (word & (bit - 1)).count_ones() as usize)
    }

    /// The front (`back` false) or back PNMT record of a filled shaft: its
    /// [`Self::pnmt_layout`] words.
    pub fn record(&self, rank: usize, back: bool) -> &'a [u32] {
        let words = self.pnmt_layout.words();
        let i = (2 * rank + back as usize) * words;
        &self.pnmt[i..i + words]
    }

    /// Candidate entries of a filled shaft.
    pub fn entries(&self, rank: usize) -> &'a [u32] {
        &self.candidates[self.candidate_offsets[rank] as usize..self.candidate_offsets[rank + 1] as usize]
    }

    /// Memory of each variant, bytes: (voxel grid, binary incl. slots and ranks, candidates, PNMT).
    pub fn memory(&self) -> (u64, u64, u64, u64) {
        let b = |s: &[u32]| (s.len() * 4) as u64;
        (
            b(self.voxel_offsets) + b(self.voxel_triangles) + 96,
            b(self.slots) + b(self.bits) + b(self.ranks),
            b(self.candidate_offsets) + b(self.candidates),
            b(self.pnmt),
        )
    }
}
