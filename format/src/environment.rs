//! The environment (`ENVH`, `ENVR`, `ENVP`, `ENVT`): the light arriving from beyond the scene in
//! every direction, as an equirectangular radiance map, its GGX-prefiltered levels for the
//! split-sum specular, its diffuse irradiance as nine spherical-harmonic coefficients, and an
//! alias table that draws directions in proportion to the light (FORMAT.md, "Environment").
//!
//! Everything a reader needs to find a texel is defined here once: the mapping between directions
//! and map coordinates, the levels' layout and the table's density. `shaders/common/environment.glsl`
//! mirrors it and a test checks the two agree.
//!
//! Directions map as Mitsuba 3's `envmap` emitter maps them (y up): u = atan2(x, −z) / 2π
//! wrapped into [0, 1), v = acos(y) / π, so that row 0 is the zenith, the image's left and right
//! edges look along −z, its centre column along +z and its first quarter along +x.

use glam::Vec3;

use crate::error::{FormatError, Result};
pub use crate::gpu::{EnvironmentCell, EnvironmentHeader};
use crate::read::KilnFile;
use crate::sections::{ENVIRONMENT_FILTERED, ENVIRONMENT_HEADER, ENVIRONMENT_MAP, ENVIRONMENT_TABLE};

/// The environment's four section kinds: present together or not at all.
pub const ENVIRONMENT_KINDS: [crate::SectionKind; 4] =
    [ENVIRONMENT_HEADER, ENVIRONMENT_MAP, ENVIRONMENT_FILTERED, ENVIRONMENT_TABLE];

/// Width of the radiance map, at most (its height is half its width).
pub const MAX_MAP_WIDTH: u32 = 8192;
/// Width of the prefiltered level 0 and of the sampling table, at most.
pub const MAX_FILTERED_WIDTH: u32 = 1024;
/// Prefiltered levels, at most.
pub const MAX_FILTERED_LEVELS: u32 = 10;

const _: () = assert!(size_of::<EnvironmentHeader>() == 192);
const _: () = assert!(size_of::<EnvironmentCell>() == 16);

/// Map coordinates (u, v) in [0, 1)² of a unit direction (see the module's convention).
pub fn direction_to_uv(d: Vec3) -> [f32; 2] {
    let u = d.x.atan2(-d.z) * (0.5 * std::f32::consts::FRAC_1_PI);
    let u = u - u.floor();
    let v = d.y.clamp(-1.0, 1.0).acos() * std::f32::consts::FRAC_1_PI;
    [if u >= 1.0 { 0.0 } else { u }, v]
}

/// The unit direction at map coordinates (u, v).
pub fn uv_to_direction(u: f32, v: f32) -> Vec3 {
    let (phi, theta) = (2.0 * std::f32::consts::PI * u, std::f32::consts::PI * v);
    let (st, ct) = theta.sin_cos();
    Vec3::new(st * phi.sin(), ct, -st * phi.cos())
}

/// Row-major index of the texel of a `w` × `h` map that holds unit direction `d`.
pub fn texel_of(d: Vec3, w: u32, h: u32) -> usize {
    let [u, v] = direction_to_uv(d);
    let x = ((u * w as f32) as u32).min(w - 1);
    let y = ((v * h as f32) as u32).min(h - 1);
    (y * w + x) as usize
}

/// Solid angle of each texel of row `y` of a `width` × `height` map, sr.
pub fn texel_solid_angle(y: u32, width: u32, height: u32) -> f64 {
    let t0 = std::f64::consts::PI * y as f64 / height as f64;
    let t1 = std::f64::consts::PI * (y + 1) as f64 / height as f64;
    (t0.cos() - t1.cos()) * std::f64::consts::TAU / width as f64
}

/// The nine real spherical-harmonic basis functions at unit direction n (bands 0–2, in the order
/// of [`EnvironmentHeader::sh`]).
pub fn sh_basis(n: Vec3) -> [f32; 9] {
    let (x, y, z) = (n.x, n.y, n.z);
    [
        0.282_094_8,
        0.488_602_5 * y,
        0.488_602_5 * z,
        0.488_602_5 * x,
        1.092_548_4 * x * y,
        1.092_548_4 * y * z,
        0.315_391_57 * (3.0 * z * z - 1.0),
        1.092_548_4 * x * z,
        0.546_274_2 * (x * x - y * y),
    ]
}

impl EnvironmentHeader {
    /// Width and height of prefiltered level `i` (each halving, at least 2 × 1).
    pub fn filtered_extent(&self, i: u32) -> [u32; 2] {
        let w = (self.filtered[0] >> i).max(2);
        [w, w / 2]
    }

    /// Index of level `i`'s first texel within `ENVP`.
    pub fn filtered_offset(&self, i: u32) -> usize {
        (0..i).map(|l| self.filtered_extent(l)).map(|[w, h]| w as usize * h as usize).sum()
    }

    /// Texels in `ENVP`.
    pub fn filtered_texels(&self) -> usize {
        self.filtered_offset(self.filtered[2])
    }

    /// Elements of `ENVR`, `ENVP` and `ENVT` (of a header within its limits).
    pub fn section_counts(&self) -> [u64; 3] {
        [
            self.map[0] as u64 * self.map[1] as u64,
            self.filtered_texels() as u64,
            self.table[0] as u64 * self.table[1] as u64,
        ]
    }

    /// Mean radiance over the cosine-weighted hemisphere around unit normal `n` (irradiance / π)
    /// from the spherical harmonics, clamped at zero (band 2 rings below zero behind a bright
    /// source).
    pub fn irradiance_over_pi(&self, n: Vec3) -> Vec3 {
        let b = sh_basis(n);
        let mut e = Vec3::ZERO;
        for (c, w) in self.sh.iter().zip(b) {
            e += Vec3::new(c[0], c[1], c[2]) * w;
        }
        e.max(Vec3::ZERO)
    }

    /// Checks the fields against the limits a reader relies on; the message names the field.
    pub fn check(&self) -> Result<()> {
        let bad = |what: String| Err(FormatError::invalid(format!("environment: {what}")));
        let [w, h, z0, z1] = self.map;
        if w == 0 || w > MAX_MAP_WIDTH || w != 2 * h || z0 != 0 || z1 != 0 {
            return bad(format!("radiance map of {w}x{h} (width 2..={MAX_MAP_WIDTH}, twice the height)"));
        }
        let [fw, fh, levels, first] = self.filtered;
        if fw == 0 || fw > MAX_FILTERED_WIDTH.min(w) || fw != 2 * fh {
            return bad(format!("prefiltered level 0 of {fw}x{fh} for a {w}x{h} map"));
        }
        if !(1..=MAX_FILTERED_LEVELS).contains(&levels) || first as u64 != w as u64 * h as u64 {
            return bad(format!(
                "{levels} prefiltered levels (1..={MAX_FILTERED_LEVELS}) or first texel {first}"
            ));
        }
        let [tw, th, z2, z3] = self.table;
        if tw == 0 || tw > MAX_FILTERED_WIDTH.min(w) || tw != 2 * th || z2 != 0 || z3 != 0 {
            return bad(format!("sampling table of {tw}x{th} for a {w}x{h} map"));
        }
        if self.sh.iter().any(|c| c[3] != 0.0 || !c.iter().all(|x| x.is_finite())) {
            return bad("spherical-harmonic coefficients not finite (or their w not zero)".into());
        }
        Ok(())
    }
}

impl EnvironmentCell {
    /// Solid-angle density of a direction in this cell at polar angle θ (sin θ given).
    pub fn pdf(&self, sin_theta: f32) -> f32 {
        if sin_theta > 0.0 { self.density / sin_theta } else { 0.0 }
    }
}

/// A validated environment: its header and sections, borrowed from the file.
#[derive(Debug, Clone, Copy)]
pub struct Environment<'a> {
    /// The header.
    pub header: EnvironmentHeader,
    /// The radiance map, `E5B9G9R9` texels, row 0 the zenith.
    pub map: &'a [u32],
    /// The prefiltered levels, `E5B9G9R9`, level 0 (mirror) first; level i is for roughness
    /// i / (levels − 1).
    pub filtered: &'a [u32],
    /// The sampling table, one cell per texel of a table-sized map.
    pub table: &'a [EnvironmentCell],
}

impl<'a> Environment<'a> {
    /// The file's environment, validated (`None` when it has none): the header's limits, every
    /// section's length against it, and the table's entries (probabilities in [0, 1], aliases in
    /// range, densities finite and non-negative). The error names the section.
    pub fn read(file: &'a KilnFile) -> Result<Option<Environment<'a>>> {
        let Some(header) = file.group_header::<EnvironmentHeader>(&ENVIRONMENT_KINDS, "environment")? else {
            return Ok(None);
        };
        header.check()?;
        // Each length against the header before decoding (`pod_exact`).
        let [map_texels, filtered_texels, cells] = header.section_counts();
        let map: &[u32] = file.pod_exact(ENVIRONMENT_MAP, 0, map_texels, "environment-map")?.unwrap_or(&[]);
        let filtered: &[u32] =
            file.pod_exact(ENVIRONMENT_FILTERED, 0, filtered_texels, "environment-filtered")?.unwrap_or(&[]);
        let table: &[EnvironmentCell] =
            file.pod_exact(ENVIRONMENT_TABLE, 0, cells, "environment-table")?.unwrap_or(&[]);
        let cells = cells as usize;
        for (i, c) in table.iter().enumerate() {
            let density_ok = |d: f32| d.is_finite() && d >= 0.0;
            if !((0.0..=1.0).contains(&c.keep)
                && (c.alias as usize) < cells
                && density_ok(c.density)
                && density_ok(c.alias_density))
            {
                return Err(FormatError::invalid(format!("environment-table: cell {i} is out of range")));
            }
        }
        Ok(Some(Environment { header: *header, map, filtered, table }))
    }

    /// Radiance arriving from unit direction `d`: the map's texel, nearest (what the sampling
    /// table's piecewise-constant density assumes).
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        Vec3::from(crate::probes::decode_rgb9e5(
            self.map[texel_of(d, self.header.map[0], self.header.map[1])],
        ))
    }

    /// A direction drawn from the table with three uniforms in [0, 1) (the first picks the cell
    /// and, by its fraction, whether the cell keeps the draw; the other two place it uniformly in
    /// the cell's (u, v) rectangle), and its solid-angle density; `None` where it has none (a
    /// black map, a pole). What `shaders/common/environment.glsl`'s `env_sample` does.
    pub fn sample(&self, xi: [f32; 3]) -> Option<(Vec3, f32)> {
        let [w, h] = [self.header.table[0], self.header.table[1]];
        let cells = w * h;
        let scaled = xi[0] * cells as f32;
        let mut cell = (scaled as u32).min(cells - 1);
        let c = self.table[cell as usize];
        let mut density = c.density;
        if scaled - cell as f32 >= c.keep {
            (cell, density) = (c.alias, c.alias_density);
        }
        let (u, v) = (((cell % w) as f32 + xi[1]) / w as f32, ((cell / w) as f32 + xi[2]) / h as f32);
        let s = (std::f32::consts::PI * v).sin();
        let pdf = if s > 0.0 { density / s } else { 0.0 };
        (pdf > 0.0).then(|| (uv_to_direction(u, v), pdf))
    }

    /// Solid-angle density with which the table draws unit direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let cell = texel_of(d, self.header.table[0], self.header.table[1]);
        self.table[cell].pdf((1.0 - d.y * d.y).max(0.0).sqrt())
    }
}

/// Walker's alias table of `weights` (Vose's construction): per entry, the probability that a
/// draw landing on it keeps it and the entry it takes otherwise, so that entry i is chosen with
/// probability weights[i] / Σ weights. Empty weights (or all zero) give entries that keep
/// themselves.
pub fn alias_table(weights: &[f64]) -> Vec<(f32, u32)> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let mut table: Vec<(f32, u32)> = (0..n as u32).map(|i| (1.0, i)).collect();
    if !(total > 0.0) {
        return table;
    }
    let mut scaled: Vec<f64> = weights.iter().map(|w| w * n as f64 / total).collect();
    // Each entry keeps itself until a smaller one is paired with it.
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        table[s] = (scaled[s] as f32, l as u32);
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // What is left keeps itself (rounding leaves entries near 1 in either list).
    table
}
