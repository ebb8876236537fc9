//! The `probes` stage: an irradiance probe volume over the scene, path traced on the CPU
//! (FORMAT.md, "Irradiance probes"; the player's `--gi probes` reads it).
//!
//! Per probe, [`ProbeLayout::rays`] rays leave along spherical Fibonacci directions; each
//! returns the radiance arriving along it (path traced, [`trace`]) and the distance to what it
//! hit. Those samples, with next-event samples of the emissive triangles, are projected onto an
//! octahedral map of irradiance (the mean cosine-weighted radiance E/π around each texel's
//! direction) and one of distance moments (DDGI's: the mean and mean square of the distance,
//! weighted by cos^[`DISTANCE_EXPONENT`] around each texel's direction), from which the player's
//! Chebyshev test keeps light from leaking through walls. Before that each probe is moved out of
//! geometry (when a quarter of its rays hit back faces of single-sided surfaces, or 5/8 the backs
//! of double-sided ones by their winding, it is inside: it moves through the nearest back face) and away from surfaces closer than [`MIN_SURFACE_DISTANCE`] spacings, within
//! [`MAX_OFFSET`] spacings of its grid point; one still inside is switched off (DDGI's
//! relocation and classification, Majercik et al. 2021).

pub mod trace;

use glam::Vec3;
use kiln_format::manifest::Bounds;
use kiln_format::probes::{
    MAX_ATLAS_EDGE, MAX_PROBE_AXIS, ProbeHeader, ProbeState, border_source, encode_rgb9e5, texel_direction,
};
use kiln_format::sections::{PROBE_GRID, PROBE_IRRADIANCE, PROBE_STATES, PROBE_VISIBILITY};
use rayon::prelude::*;

use self::trace::{Side, Tracer, fibonacci_direction, path_rng};
use super::{BakeContext, Sections};

/// Interior texels along an irradiance tile's edge (8 × 8 directions: irradiance is smooth).
pub const IRRADIANCE_TEXELS: u32 = 8;
/// Interior texels along a visibility tile's edge (14 × 14, 16 × 16 with the border: DDGI's).
pub const VISIBILITY_TEXELS: u32 = 14;
/// Distances are clamped to this many spacings; rays that leave the scene count as this far.
pub const MAX_DISTANCE: f32 = 4.0;
/// The cosine power of the visibility maps' lobes (DDGI's 50: about 10° wide).
pub const DISTANCE_EXPONENT: i32 = 50;
/// Rays of each relocation test.
const RELOCATION_RAYS: u32 = 64;
/// A probe whose test rays hit back faces this often is inside geometry.
const INSIDE_FRACTION: f32 = 0.25;
/// What a back face of a double-sided surface (by its winding) counts for against
/// [`INSIDE_FRACTION`]: inside takes more than 5/8 of the rays on such backs. Exporters often mark
/// closed meshes double-sided, and a probe in one sees their backs all round (Khronos ToyCar:
/// none of 980 probes was switched off, and the ones inside its body blackened the roof); an
/// open sheet (a canopy, a cloth) covers at most half of a probe's view, which stays out.
const DOUBLE_SIDED_BACK: f32 = INSIDE_FRACTION / 0.625;
/// Probes are moved at least this many spacings from the surfaces around them (where the
/// limit on offsets allows).
pub const MIN_SURFACE_DISTANCE: f32 = 0.1;
/// A probe moves at most this many spacings from its grid point along each axis.
pub const MAX_OFFSET: f32 = 0.45;
/// Probes along the longest axis when the spacing is chosen from the scene's size.
pub const AUTO_PROBES: u32 = 16;

/// Where the probes go, decided by the plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeLayout {
    /// Grid point of probe (0, 0, 0).
    pub origin: Vec3,
    /// Distance between neighbours.
    pub spacing: f32,
    /// Probes along each axis.
    pub dims: [u32; 3],
    /// Irradiance layers (2 when something emits: its direct light in a layer of its own).
    pub layers: u32,
    /// Rays per probe.
    pub rays: u32,
    /// The least perceptual roughness of the surfaces the paths meet (`--probe-regularize`).
    pub min_roughness: f32,
}

impl ProbeLayout {
    /// Probes in the volume.
    pub fn count(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }

    /// Bytes of the four sections.
    pub fn bytes(&self) -> u64 {
        bytes_per_probe(self.layers) * self.count() + 64
    }

    /// The header of the volume (with `active` probes on).
    pub fn header(&self, active: u32) -> ProbeHeader {
        ProbeHeader {
            origin: self.origin.to_array(),
            spacing: self.spacing,
            dims: self.dims,
            irradiance_texels: IRRADIANCE_TEXELS,
            visibility_texels: VISIBILITY_TEXELS,
            layers: self.layers,
            rays: self.rays,
            max_bounces: trace::MAX_BOUNCES,
            max_distance: MAX_DISTANCE,
            active,
            reserved: [0; 2],
        }
    }
}

/// Bytes a probe takes with `layers` irradiance layers.
pub fn bytes_per_probe(layers: u32) -> u64 {
    let tile = |t: u32| ((t + 2) * (t + 2)) as u64 * 4;
    tile(IRRADIANCE_TEXELS) * layers as u64 + tile(VISIBILITY_TEXELS) + 16
}

/// The grid over `bounds`: probes `spacing` apart (given, or the longest extent over
/// [`AUTO_PROBES`] widened until the volume fits `budget` bytes), centred on the bounds, inside
/// them. The error says what to change.
pub fn layout(
    bounds: &Bounds,
    spacing: Option<f32>,
    budget: u64,
    layers: u32,
    rays: u32,
    min_roughness: f32,
) -> Result<ProbeLayout, String> {
    let (lo, hi) = (Vec3::from(bounds.min), Vec3::from(bounds.max));
    let extent = (hi - lo).max(Vec3::ZERO);
    let longest = extent.max_element();
    // round(extent / s) probes a spacing apart span extent − s ± s/2: the outermost lie a
    // quarter to three quarters of a spacing inside the bounds, off the walls that bound most
    // scenes (a probe on a wall sees half of everything through it).
    let dims_for = |s: f32| [0, 1, 2].map(|a| ((extent[a] / s).round() as u64).max(1));
    let axis_limit = (MAX_ATLAS_EDGE / (VISIBILITY_TEXELS + 2)).min(MAX_PROBE_AXIS) as u64;
    let fits_axes = |d: [u64; 3]| d.iter().all(|&n| n <= axis_limit);
    let spacing = match spacing {
        Some(s) => {
            let d = dims_for(s);
            if !fits_axes(d) {
                return Err(format!(
                    "--probe-spacing {s} puts {}x{}x{} probes over the scene's {:.4}x{:.4}x{:.4} bounds; at most {axis_limit} fit along an axis: raise it to at least {:.4}",
                    d[0],
                    d[1],
                    d[2],
                    extent.x,
                    extent.y,
                    extent.z,
                    longest / axis_limit as f32
                ));
            }
            s
        }
        None => {
            // A point-sized or empty scene still gets one probe.
            let mut s = if longest > 0.0 { longest / AUTO_PROBES as f32 } else { 1.0 };
            let bytes = |d: [u64; 3]| d.iter().product::<u64>() * bytes_per_probe(layers);
            while !fits_axes(dims_for(s)) || bytes(dims_for(s)) > budget {
                s *= 1.05;
            }
            s
        }
    };
    let dims = dims_for(spacing).map(|d| d as u32);
    let span = Vec3::new(dims[0] as f32 - 1.0, dims[1] as f32 - 1.0, dims[2] as f32 - 1.0) * spacing;
    let origin = (lo + hi) * 0.5 - span * 0.5;
    Ok(ProbeLayout { origin, spacing, dims, layers, rays, min_roughness })
}

/// One probe's bake: its state and interior texels.
struct Baked {
    state: ProbeState,
    /// E/π per irradiance texel, per layer (layer 0: all but emitters seen directly).
    irradiance: Vec<[Vec3; 2]>,
    /// (mean, mean square) distance in spacings per visibility texel.
    visibility: Vec<[f32; 2]>,
}

/// What the relocation test rays from `p` see: how many meet the inside of something, and the
/// nearest such hit and the nearest other hit (distance, direction).
struct Survey {
    inside: bool,
    nearest_back: Option<(f32, Vec3)>,
    nearest_front: Option<(f32, Vec3)>,
}

fn survey(tracer: &Tracer, p: Vec3) -> Survey {
    let (mut back, mut nearest_back, mut nearest_front) = (0.0, None::<(f32, Vec3)>, None::<(f32, Vec3)>);
    let keep = |slot: &mut Option<(f32, Vec3)>, t: f32, d: Vec3| {
        if slot.is_none_or(|(nearest, _)| t < nearest) {
            *slot = Some((t, d));
        }
    };
    for i in 0..RELOCATION_RAYS {
        let d = fibonacci_direction(i, RELOCATION_RAYS);
        let Some(h) = tracer.trace(p, d, f32::INFINITY) else { continue };
        match tracer.side(&h, d) {
            Side::Front => keep(&mut nearest_front, h.t, d),
            Side::SingleBack => {
                back += 1.0;
                keep(&mut nearest_back, h.t, d);
            }
            // A way out where the probe is inside, a surface to keep away from where it is not.
            Side::DoubleBack => {
                back += DOUBLE_SIDED_BACK;
                keep(&mut nearest_back, h.t, d);
                keep(&mut nearest_front, h.t, d);
            }
        }
    }
    Survey { inside: back > INSIDE_FRACTION * RELOCATION_RAYS as f32, nearest_back, nearest_front }
}

/// Moves the probe at grid point `g` out of geometry and away from surfaces: its position, or
/// `None` when it stays inside.
fn relocate(tracer: &Tracer, g: Vec3, spacing: f32) -> Option<Vec3> {
    let limit = MAX_OFFSET * spacing;
    let clamp = |p: Vec3| g + (p - g).clamp(Vec3::splat(-limit), Vec3::splat(limit));
    let mut p = g;
    for _ in 0..4 {
        let Survey { inside, nearest_back, nearest_front } = survey(tracer, p);
        let moved = match (inside, nearest_back, nearest_front) {
            // Through the nearest back face, a little beyond it.
            (true, Some((t, d)), _) => clamp(p + d * (t + MIN_SURFACE_DISTANCE * spacing)),
            (false, _, Some((t, d))) if t < MIN_SURFACE_DISTANCE * spacing => {
                clamp(p - d * (MIN_SURFACE_DISTANCE * spacing - t))
            }
            _ if inside => return None,
            _ => return Some(p),
        };
        if moved == p {
            return (!inside).then_some(p);
        }
        p = moved;
    }
    // Still moving after four steps: on only if it ended outside.
    (!survey(tracer, p).inside).then_some(p)
}

/// What a probe's samples add to its texels: the direction, the light of each layer (already
/// divided by the sampling density) and, for rays, the distance in spacings.
struct Sample {
    d: Vec3,
    light: [Vec3; 2],
    distance: Option<f32>,
}

/// Bakes probe `index` at grid point `g`.
fn bake_probe(tracer: &Tracer, layout: &ProbeLayout, index: u32, g: Vec3) -> Baked {
    let spacing = layout.spacing;
    let zero = || Baked {
        state: ProbeState::default(),
        irradiance: vec![[Vec3::ZERO; 2]; (IRRADIANCE_TEXELS * IRRADIANCE_TEXELS) as usize],
        visibility: vec![[0.0; 2]; (VISIBILITY_TEXELS * VISIBILITY_TEXELS) as usize],
    };
    let Some(p) = relocate(tracer, g, spacing) else { return zero() };
    let n = layout.rays;
    // A quarter as many next-event samples of the emissive triangles, combined with the rays
    // that hit them by the balance heuristic: a small lamp seen by few rays still lights evenly.
    let m = if tracer.has_emitters() { n / 4 } else { 0 };
    // As many again of the environment through its table, against the rays that escape: a sun
    // or a softbox a few degrees across lights the probe without waiting for a ray to find it.
    let q = if tracer.sky.sampled() { n / 4 } else { 0 };
    let uniform = n as f32 / (4.0 * std::f32::consts::PI);
    let mut samples = Vec::with_capacity((n + m) as usize);
    for i in 0..n {
        let d = fibonacci_direction(i, n);
        let mut rng = path_rng(index, i);
        let sample = match tracer.trace(p, d, f32::INFINITY) {
            None => {
                let sky = tracer.sky.radiance(d) / (uniform + q as f32 * tracer.sky.pdf(d));
                Sample { d, light: [sky, Vec3::ZERO], distance: None }
            }
            Some(h) => {
                let distance = Some(h.t / spacing);
                if tracer.inside(&h, d) {
                    // The inside of something: no light comes from there.
                    Sample { d, light: [Vec3::ZERO; 2], distance }
                } else {
                    let emitted = tracer.emission(&h, d) / (uniform + m as f32 * tracer.emitter_pdf(&h, d));
                    let reflected = tracer.reflected(h, d, &mut rng) / uniform;
                    Sample { d, light: [reflected, emitted], distance }
                }
            }
        };
        samples.push(sample);
    }
    for j in 0..m {
        let mut rng = path_rng(index, n + j);
        if let Some((d, le, pdf)) = tracer.sample_emitter(p, Vec3::ZERO, &mut rng)
            && le != Vec3::ZERO
        {
            samples.push(Sample { d, light: [Vec3::ZERO, le / (uniform + m as f32 * pdf)], distance: None });
        }
    }
    for j in 0..q {
        let mut rng = path_rng(index, n + m + j);
        if let Some((d, le, pdf)) = tracer.sky.sample(j, q, &mut rng)
            && le != Vec3::ZERO
            && tracer.trace(p, d, f32::INFINITY).is_none()
        {
            samples.push(Sample { d, light: [le / (uniform + q as f32 * pdf), Vec3::ZERO], distance: None });
        }
    }
    let ti = IRRADIANCE_TEXELS;
    let irradiance = (0..ti * ti)
        .map(|k| {
            let t = texel_direction(k % ti, k / ti, ti);
            let mut sum = [Vec3::ZERO; 2];
            for s in &samples {
                let c = t.dot(s.d);
                if c > 0.0 {
                    sum[0] += s.light[0] * c;
                    sum[1] += s.light[1] * c;
                }
            }
            sum.map(|e| e / std::f32::consts::PI)
        })
        .collect();
    let tv = VISIBILITY_TEXELS;
    let visibility = (0..tv * tv)
        .map(|k| {
            let t = texel_direction(k % tv, k / tv, tv);
            let (mut w_sum, mut d1, mut d2) = (0.0f32, 0.0f32, 0.0f32);
            for s in samples.iter().take(n as usize) {
                let c = t.dot(s.d);
                if c > 0.0 {
                    let w = c.powi(DISTANCE_EXPONENT);
                    let d = s.distance.unwrap_or(MAX_DISTANCE).min(MAX_DISTANCE);
                    (w_sum, d1, d2) = (w_sum + w, d1 + w * d, d2 + w * d * d);
                }
            }
            if w_sum > 0.0 { [d1 / w_sum, d2 / w_sum] } else { [MAX_DISTANCE, MAX_DISTANCE * MAX_DISTANCE] }
        })
        .collect();
    Baked { state: ProbeState { offset: (p - g).to_array(), active: 1.0 }, irradiance, visibility }
}

/// The four sections of a volume of `probes` (in `PRBS` order) laid out by `layout`.
fn sections(layout: &ProbeLayout, probes: &[Baked]) -> Sections {
    let active = probes.iter().filter(|p| p.state.active == 1.0).count() as u32;
    let header = layout.header(active);
    let [iw, ih, il] = header.irradiance_extent();
    let [vw, vh, vl] = header.visibility_extent();
    let mut irradiance = vec![0u32; (iw * ih * il) as usize];
    let mut visibility = vec![[0u16; 2]; (vw * vh * vl) as usize];
    let [dx, dy, dz] = layout.dims;
    for z in 0..dz {
        for y in 0..dy {
            for x in 0..dx {
                let probe = &probes[header.index(x, y, z)];
                let n = IRRADIANCE_TEXELS as i32;
                for layer in 0..layout.layers {
                    for j in -1..=n {
                        for i in -1..=n {
                            let (si, sj) = border_source(i, j, n);
                            let e = probe.irradiance[(sj * IRRADIANCE_TEXELS + si) as usize][layer as usize];
                            let (ax, ay) =
                                (x * (n as u32 + 2) + (i + 1) as u32, y * (n as u32 + 2) + (j + 1) as u32);
                            let at = ((layer * dz + z) * ih + ay) * iw + ax;
                            irradiance[at as usize] = encode_rgb9e5(e.to_array());
                        }
                    }
                }
                let n = VISIBILITY_TEXELS as i32;
                for j in -1..=n {
                    for i in -1..=n {
                        let (si, sj) = border_source(i, j, n);
                        let v = probe.visibility[(sj * VISIBILITY_TEXELS + si) as usize];
                        let (ax, ay) =
                            (x * (n as u32 + 2) + (i + 1) as u32, y * (n as u32 + 2) + (j + 1) as u32);
                        visibility[((z * vh + ay) * vw + ax) as usize] =
                            v.map(|d| half::f16::from_f32(d).to_bits());
                    }
                }
            }
        }
    }
    let states: Vec<ProbeState> = probes.iter().map(|p| p.state).collect();
    let mut out = Sections::default();
    out.push(PROBE_GRID, 0, bytemuck::bytes_of(&header).to_vec());
    out.push(PROBE_STATES, 0, bytemuck::cast_slice(&states).to_vec());
    out.push(PROBE_IRRADIANCE, 0, bytemuck::cast_slice(&irradiance).to_vec());
    out.push(PROBE_VISIBILITY, 0, bytemuck::cast_slice(&visibility).to_vec());
    out
}

/// The stage: relocates and bakes every probe of the plan's layout on all cores (the bytes do not
/// depend on how many), then lays out the atlases.
pub fn stage(ctx: &BakeContext) -> Sections {
    let Some(layout) = ctx.plan.probes else { return Sections::default() };
    let luminance = super::materials::emitted_luminance(ctx);
    let tracer = Tracer::new(
        ctx.shading(),
        &ctx.scene.uvs,
        &ctx.triangle_materials,
        match ctx.environment() {
            Some(e) => trace::Sky::Environment(e),
            None => trace::Sky::Constant(Vec3::from(ctx.scene.sky.radiance)),
        },
        luminance.as_deref(),
        layout.min_roughness,
    );
    ctx.progress.count("probes", layout.count());
    let header = layout.header(0);
    let probes: Vec<Baked> = (0..layout.count() as u32)
        .into_par_iter()
        .map(|i| {
            let [dx, dy, _] = layout.dims;
            let (x, y, z) = (i % dx, i / dx % dy, i / (dx * dy));
            let baked = bake_probe(&tracer, &layout, i, header.grid_point(x, y, z));
            ctx.progress.inc(1);
            baked
        })
        .collect();
    sections(&layout, &probes)
}
