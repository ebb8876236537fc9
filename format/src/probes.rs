//! The irradiance probe volume (`PRBG`, `PRBS`, `PRBI`, `PRBV`): a regular grid of probes over
//! the scene, each holding the light arriving at it from every direction in octahedral maps,
//! baked by the compiler's path tracer (FORMAT.md, "Irradiance probes").
//!
//! Everything a reader needs to find a texel is defined here once: the header, the atlas layout
//! (one tile per probe, a one-texel border around each tile's interior so that bilinear filtering
//! wraps across the octahedron's folded edges), the octahedral mapping and the shared-exponent
//! texel encoding. `shaders/common/probes.glsl` mirrors the mapping and is checked against it.

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

use crate::error::{FormatError, Result};
use crate::read::KilnFile;
use crate::sections::{PROBE_GRID, PROBE_IRRADIANCE, PROBE_STATES, PROBE_VISIBILITY};

/// The volume's four section kinds: present together or not at all.
pub const PROBE_KINDS: [crate::SectionKind; 4] =
    [PROBE_GRID, PROBE_STATES, PROBE_IRRADIANCE, PROBE_VISIBILITY];

/// Probes along one axis, at most: with two irradiance layers a volume's array image has at most
/// 2 × 128 = 256 layers, Vulkan's guaranteed `maxImageArrayLayers`.
pub const MAX_PROBE_AXIS: u32 = 128;
/// Interior texels along a tile's edge, at most (the atlas must also fit [`MAX_ATLAS_EDGE`]).
pub const MAX_PROBE_TEXELS: u32 = 32;
/// Width and height of an atlas image, at most (Vulkan's guaranteed `maxImageDimension2D`).
pub const MAX_ATLAS_EDGE: u32 = 4096;

/// Header of the probe volume (`PRBG`, one element, 64 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
#[repr(C)]
pub struct ProbeHeader {
    /// World position of probe (0, 0, 0) before its offset.
    pub origin: [f32; 3],
    /// Distance between neighbouring probes along every axis (scene units).
    pub spacing: f32,
    /// Probes along x, y, z.
    pub dims: [u32; 3],
    /// Interior texels along the edge of an irradiance tile.
    pub irradiance_texels: u32,
    /// Interior texels along the edge of a visibility tile.
    pub visibility_texels: u32,
    /// Irradiance layers: 1 (light other than emissive surfaces' direct light) or 2 (then
    /// emissive surfaces' direct light in the second).
    pub layers: u32,
    /// Rays traced per probe.
    pub rays: u32,
    /// The most scattering events a baked path counts after the probe's ray.
    pub max_bounces: u32,
    /// Distances stored in the visibility maps are clamped to this many spacings (a ray that
    /// leaves the scene counts as this far).
    pub max_distance: f32,
    /// Probes switched on (the rest lie inside geometry).
    pub active: u32,
    /// Zero.
    pub reserved: [u32; 2],
}

const _: () = assert!(size_of::<ProbeHeader>() == 64);

/// One probe's state (`PRBS`, 16 bytes a probe, x fastest, then y, then z): where the bake moved
/// it from its grid point and whether it is on.
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
#[repr(C)]
pub struct ProbeState {
    /// Offset from the grid point, scene units; each component within ±½ spacing.
    pub offset: [f32; 3],
    /// 1: on; 0: off (inside geometry; its texels are zero and readers skip it).
    pub active: f32,
}

impl ProbeHeader {
    /// Probes in the volume.
    pub fn count(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }

    /// Index of probe (x, y, z) in `PRBS` order.
    pub fn index(&self, x: u32, y: u32, z: u32) -> usize {
        (x + self.dims[0] * (y + self.dims[1] * z)) as usize
    }

    /// Grid point of probe (x, y, z) (without its offset).
    pub fn grid_point(&self, x: u32, y: u32, z: u32) -> Vec3 {
        Vec3::from(self.origin) + Vec3::new(x as f32, y as f32, z as f32) * self.spacing
    }

    /// Elements of `PRBS`, `PRBI` and `PRBV` (of a header within its limits).
    pub fn section_counts(&self) -> [u64; 3] {
        let texels = |e: [u32; 3]| e.iter().map(|&d| d as u64).product::<u64>();
        [self.count(), texels(self.irradiance_extent()), texels(self.visibility_extent())]
    }

    /// Width, height and layers of the irradiance atlas.
    pub fn irradiance_extent(&self) -> [u32; 3] {
        let tile = self.irradiance_texels + 2;
        [self.dims[0] * tile, self.dims[1] * tile, self.dims[2] * self.layers]
    }

    /// Width, height and layers of the visibility atlas.
    pub fn visibility_extent(&self) -> [u32; 3] {
        let tile = self.visibility_texels + 2;
        [self.dims[0] * tile, self.dims[1] * tile, self.dims[2]]
    }

    /// Checks the header's fields against the limits a reader relies on; the message names the
    /// field.
    pub fn check(&self) -> Result<()> {
        let bad = |what: String| Err(FormatError::invalid(format!("probe volume: {what}")));
        if !(Vec3::from(self.origin).is_finite() && self.spacing.is_finite() && self.spacing > 0.0) {
            return bad(format!(
                "origin {:?} or spacing {} is not finite and positive",
                self.origin, self.spacing
            ));
        }
        if self.dims.iter().any(|&d| d == 0 || d > MAX_PROBE_AXIS) {
            return bad(format!("dims {:?} outside 1..={MAX_PROBE_AXIS}", self.dims));
        }
        for (name, t) in [("irradiance", self.irradiance_texels), ("visibility", self.visibility_texels)] {
            if !(1..=MAX_PROBE_TEXELS).contains(&t) {
                return bad(format!("{name} tiles of {t} texels, outside 1..={MAX_PROBE_TEXELS}"));
            }
        }
        if !(1..=2).contains(&self.layers) {
            return bad(format!("{} irradiance layers (1 or 2)", self.layers));
        }
        for (name, e) in [("irradiance", self.irradiance_extent()), ("visibility", self.visibility_extent())]
        {
            if e[0] > MAX_ATLAS_EDGE || e[1] > MAX_ATLAS_EDGE {
                return bad(format!("the {name} atlas is {}x{}, beyond {MAX_ATLAS_EDGE}", e[0], e[1]));
            }
        }
        if !(self.max_distance.is_finite() && self.max_distance > 0.0) || self.active as u64 > self.count() {
            return bad(format!(
                "max distance {} or {} active probes of {}",
                self.max_distance,
                self.active,
                self.count()
            ));
        }
        if self.reserved != [0; 2] {
            return bad("reserved words are not zero".into());
        }
        Ok(())
    }
}

/// A validated probe volume: its header and sections, borrowed from the file.
#[derive(Debug, Clone, Copy)]
pub struct ProbeVolume<'a> {
    /// The header.
    pub header: ProbeHeader,
    /// One state per probe.
    pub states: &'a [ProbeState],
    /// The irradiance atlas: E5B9G9R9 texels, rows of `irradiance_extent()[0]`, layer after layer.
    pub irradiance: &'a [u32],
    /// The visibility atlas: binary16 (mean, mean square) of distance in spacings per texel.
    pub visibility: &'a [[u16; 2]],
}

impl<'a> ProbeVolume<'a> {
    /// The file's probe volume, validated (`None` when it has none): the header's limits, every
    /// section's length against it, the states, and the visibility texels finite and
    /// non-negative. The error names the section.
    pub fn read(file: &'a KilnFile) -> Result<Option<ProbeVolume<'a>>> {
        let Some(header) = file.group_header::<ProbeHeader>(&PROBE_KINDS, "probe volume")? else {
            return Ok(None);
        };
        header.check()?;
        // Each length against the header before decoding (`pod_exact`).
        let [probes, irradiance_texels, visibility_texels] = header.section_counts();
        let states: &[ProbeState] = file.pod_exact(PROBE_STATES, 0, probes, "probe-states")?.unwrap_or(&[]);
        let irradiance: &[u32] =
            file.pod_exact(PROBE_IRRADIANCE, 0, irradiance_texels, "probe-irradiance")?.unwrap_or(&[]);
        let visibility: &[[u16; 2]] =
            file.pod_exact(PROBE_VISIBILITY, 0, visibility_texels, "probe-visibility")?.unwrap_or(&[]);
        let half = header.spacing * 0.5;
        let mut active = 0;
        for (i, s) in states.iter().enumerate() {
            let on = match s.active {
                1.0 => true,
                0.0 => false,
                _ => {
                    return Err(FormatError::invalid(format!(
                        "probe-states: probe {i} is neither on nor off"
                    )));
                }
            };
            active += on as u32;
            // A little above half a spacing: the bake clamps in f32.
            if s.offset.iter().any(|o| !(o.abs() <= half * 1.001)) {
                return Err(FormatError::invalid(format!(
                    "probe-states: probe {i} moved {:?}, beyond half a spacing ({half})",
                    s.offset
                )));
            }
        }
        if active != header.active {
            return Err(FormatError::invalid(format!(
                "probe-states: {active} probes on, the header says {}",
                header.active
            )));
        }
        let finite_non_negative = |h: u16| {
            let v = half::f16::from_bits(h).to_f32();
            v.is_finite() && v >= 0.0
        };
        if let Some(i) = visibility.iter().position(|t| !t.iter().all(|&h| finite_non_negative(h))) {
            return Err(FormatError::invalid(format!(
                "probe-visibility: texel {i} is negative, infinite or NaN"
            )));
        }
        Ok(Some(ProbeVolume { header: *header, states, irradiance, visibility }))
    }
}

/// The octahedral mapping of directions onto [−1, 1]² (Cigolle et al., JCGT 2014): the upper
/// hemisphere (z ≥ 0) projected onto the diamond |x| + |y| ≤ 1, the lower one folded over its
/// edges into the corners. The same as the PNMT records' normals and the G-buffer's.
pub use crate::linespace::{oct_decode, oct_encode};

/// The direction of interior texel (i, j) of a tile of `n` × `n` interior texels: its centre's
/// octahedral point.
pub fn texel_direction(i: u32, j: u32, n: u32) -> Vec3 {
    let e = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32 * 2.0 - 1.0;
    oct_decode(e)
}

/// The interior texel a border texel (i, j) of a tile copies, i and j in −1..=n: across an edge
/// the octahedron folds, so the neighbour of an edge texel is its mirror along that edge, and a
/// corner's is the opposite corner.
pub fn border_source(i: i32, j: i32, n: i32) -> (u32, u32) {
    let mirror = |k: i32| n - 1 - k;
    let (si, sj) = match (i, j) {
        (-1, -1) => (n - 1, n - 1),
        (x, -1) if x == n => (0, n - 1),
        (-1, y) if y == n => (n - 1, 0),
        (x, y) if x == n && y == n => (0, 0),
        (x, -1) => (mirror(x), 0),
        (x, y) if y == n => (mirror(x), n - 1),
        (-1, y) => (0, mirror(y)),
        (x, y) if x == n => (n - 1, mirror(y)),
        (x, y) => (x, y),
    };
    (si as u32, sj as u32)
}

/// Bias of the shared exponent (EXT_texture_shared_exponent: B = 15, N = 9 mantissa bits).
const E5_BIAS: i32 = 15;
const E5_MANTISSA: i32 = 9;

/// `rgb` (non-negative; NaN counts as 0, values beyond 65,408 clamp) as Vulkan's
/// `E5B9G9R9_UFLOAT_PACK32`: red in bits 0–8, green 9–17, blue 18–26, the shared exponent 27–31
/// (the rounding of the extension's specification).
pub fn encode_rgb9e5(rgb: [f32; 3]) -> u32 {
    let max_value = 511.0 / 512.0 * 65536.0;
    let c = rgb.map(|x| if x > 0.0 { x.min(max_value) } else { 0.0 });
    let maxc = c[0].max(c[1]).max(c[2]);
    if maxc <= 0.0 {
        return 0;
    }
    let mut exp = (maxc.log2().floor() as i32).max(-E5_BIAS - 1) + 1 + E5_BIAS;
    let scale = |e: i32| 2f32.powi(e - E5_BIAS - E5_MANTISSA);
    if (maxc / scale(exp) + 0.5).floor() as i32 == 1 << E5_MANTISSA {
        exp += 1;
    }
    let m = c.map(|x| ((x / scale(exp) + 0.5).floor() as u32).min(511));
    m[0] | m[1] << 9 | m[2] << 18 | (exp as u32) << 27
}

/// The linear RGB of an `E5B9G9R9` texel.
pub fn decode_rgb9e5(t: u32) -> [f32; 3] {
    let scale = 2f32.powi((t >> 27) as i32 - E5_BIAS - E5_MANTISSA);
    [t & 511, (t >> 9) & 511, (t >> 18) & 511].map(|m| m as f32 * scale)
}
