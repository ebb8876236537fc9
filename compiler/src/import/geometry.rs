//! Geometry helpers shared by the importers: coordinate checks and normal generation (flat,
//! smooth with an optional crease angle, or by OBJ smoothing groups), splitting vertices so that
//! each has one normal.

use glam::DVec3;

use crate::exit::{CliError, CliResult};

/// Largest coordinate magnitude accepted, in scene units. Ray–triangle tests form products of
/// three coordinate differences; beyond about 1e12 they overflow single precision.
pub const MAX_COORDINATE: f32 = 1.0e12;

/// Checks a world-space position; `what` names the element for the message.
pub fn check_position(p: [f32; 3], what: impl FnOnce() -> String) -> CliResult<()> {
    if p.iter().any(|c| !c.is_finite()) {
        return Err(CliError::input(format!("{} is not finite: {p:?}", what())));
    }
    if p.iter().any(|c| c.abs() > MAX_COORDINATE) {
        return Err(CliError::input(format!(
            "{} is {p:?}, outside the supported range of ±{MAX_COORDINATE:e} scene units",
            what()
        )));
    }
    Ok(())
}

/// Where a scene's stored positions are measured from, given its extent in world space (`lo`,
/// `hi`; empty when `lo > hi`). A scene near the origin for its size keeps the origin (`0`):
/// single precision already holds it to within about a millionth of its extent. A scene far
/// from the origin for its size (its centre more than [`REBASE_RATIO`] extents away) is stored
/// relative to its centre, rounded to a multiple of the power of two at or below its extent (a
/// round number that the subtraction of a position from loses nothing to), so that its positions
/// keep the precision a scene at the origin has. In single precision a room 10⁵ units from the
/// origin has positions only to within 8 mm (the spacing of floats there): an emitter 1 cm below
/// its ceiling is a float or two away from it, every hit point and ray offset is centimetres
/// wide, and the McGuire Cornell box so placed rendered 47 % darker than at the origin.
pub fn rebase_origin(lo: DVec3, hi: DVec3) -> DVec3 {
    if !(lo.cmple(hi).all() && lo.is_finite() && hi.is_finite()) {
        return DVec3::ZERO;
    }
    let centre = (lo + hi) * 0.5;
    let extent = (hi - lo).max_element();
    if centre.abs().max_element() <= REBASE_RATIO * extent || centre.abs().max_element() > MAX_ORIGIN {
        return DVec3::ZERO;
    }
    // A flat or point-like scene still has a scale: its distance from the origin's float spacing.
    let step = if extent > 0.0 {
        extent.log2().floor().exp2()
    } else {
        (centre.abs().max_element() * f64::from(f32::EPSILON)).log2().floor().exp2()
    };
    (centre / step).round() * step
}

/// `world` as the file stores it: relative to `origin` ([`rebase_origin`]), in single precision.
pub fn stored(world: DVec3, origin: DVec3) -> [f32; 3] {
    (world - origin).as_vec3().to_array()
}

/// A scene whose centre lies beyond this many extents from the origin is stored relative to its
/// centre ([`rebase_origin`]): 16 extents cost positions 4 bits of their 24.
pub const REBASE_RATIO: f64 = 16.0;

/// The largest origin a file records; beyond it positions are refused as out of range, as
/// before rebasing ([`MAX_COORDINATE`] bounds the stored positions).
const MAX_ORIGIN: f64 = 1.0e15;

/// Bounds of world positions in double precision, for [`rebase_origin`].
#[derive(Debug, Clone, Copy)]
pub struct Extent {
    /// Smallest coordinates seen (`+inf` when none).
    pub lo: DVec3,
    /// Largest coordinates seen (`-inf` when none).
    pub hi: DVec3,
}

impl Default for Extent {
    fn default() -> Self {
        Extent { lo: DVec3::INFINITY, hi: DVec3::NEG_INFINITY }
    }
}

impl Extent {
    /// Widens the bounds to hold `p`; non-finite points are left to the position checks.
    pub fn add(&mut self, p: DVec3) {
        if p.is_finite() {
            self.lo = self.lo.min(p);
            self.hi = self.hi.max(p);
        }
    }

    /// The origin positions are stored relative to ([`rebase_origin`]).
    pub fn origin(&self) -> DVec3 {
        rebase_origin(self.lo, self.hi)
    }
}

/// Unit normal of a triangle (counter-clockwise front), or `None` for a degenerate one.
fn face_normal(c: &[DVec3; 3]) -> Option<DVec3> {
    (c[1] - c[0]).cross(c[2] - c[0]).try_normalize()
}

/// How the triangles of a mesh share normals where the asset gives none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sharing<'a> {
    /// Every triangle its face normal.
    Flat,
    /// Angle-weighted over all triangles at a vertex, except across edges whose face normals
    /// differ by more than the crease angle (degrees; `None`: no crease).
    Smooth(Option<f64>),
    /// OBJ smoothing groups, one per triangle: `0` flat, `N` angle-weighted over the triangles
    /// of group `N` at a vertex only.
    Groups(&'a [u32]),
}

/// Per-corner normals of `triangles` under `sharing`. A smoothed corner is the angle-weighted
/// sum (Thürmer and Wüthrich 1998) of the unit face normals of the triangles it shares the
/// vertex with (each weighted by its corner angle at the vertex). A degenerate triangle
/// contributes nothing; a corner whose sum cancels out takes its face normal, or +Z.
pub fn corner_normals(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    sharing: Sharing,
) -> Vec<[[f32; 3]; 3]> {
    let p = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
    let corners: Vec<[DVec3; 3]> = triangles.iter().map(|t| t.map(p)).collect();
    let faces: Vec<Option<DVec3>> = corners.iter().map(face_normal).collect();
    let angle = |t: usize, k: usize| {
        let c = &corners[t];
        let a = (c[(k + 1) % 3] - c[k]).angle_between(c[(k + 2) % 3] - c[k]);
        if a.is_finite() { a } else { 0.0 }
    };
    let flat = |t: usize| faces[t].unwrap_or(DVec3::Z).as_vec3().to_array();
    let group = |t: usize| match sharing {
        Sharing::Flat => 0,
        Sharing::Smooth(_) => 1,
        Sharing::Groups(g) => g[t],
    };
    // Cosine of the crease angle: neighbours whose face normals' dot product falls below it are
    // not averaged in.
    let crease_cos = match sharing {
        Sharing::Smooth(Some(deg)) => Some(deg.to_radians().cos()),
        _ => None,
    };
    // Triangles at each vertex (compressed rows).
    let mut start = vec![0usize; positions.len() + 1];
    for t in triangles {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for i in 0..positions.len() {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut incident = vec![(0usize, 0usize); start[positions.len()]];
    for (ti, t) in triangles.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            incident[fill[v as usize]] = (ti, k);
            fill[v as usize] += 1;
        }
    }
    // Without a crease every corner of one group at one vertex gets the same sum: computed once.
    let mut shared: std::collections::HashMap<(u32, u32), [f32; 3]> = std::collections::HashMap::new();
    let mut out = Vec::with_capacity(triangles.len());
    for (ti, t) in triangles.iter().enumerate() {
        let g = group(ti);
        let mut n3 = [[0.0f32; 3]; 3];
        for (k, &v) in t.iter().enumerate() {
            if g == 0 {
                n3[k] = flat(ti);
                continue;
            }
            let sum = |admit: &dyn Fn(usize) -> bool| {
                let mut acc = DVec3::ZERO;
                for &(tj, kj) in &incident[start[v as usize]..start[v as usize + 1]] {
                    if let Some(n) = faces[tj]
                        && group(tj) == g
                        && admit(tj)
                    {
                        acc += n * angle(tj, kj);
                    }
                }
                acc.try_normalize().map_or_else(|| flat(ti), |n| n.as_vec3().to_array())
            };
            n3[k] = match (crease_cos, faces[ti]) {
                (Some(c), Some(own)) => sum(&|tj| faces[tj].is_some_and(|n| n.dot(own) >= c)),
                _ => *shared.entry((v, g)).or_insert_with(|| sum(&|_| true)),
            };
        }
        out.push(n3);
    }
    out
}

/// Splits vertices so that each one has one normal. Vertex `i` of the input stays vertex `i`
/// with the normal of its first corner (+Z if no triangle uses it); each further distinct normal
/// at a vertex appends a copy of it. Returns the input vertex of each output vertex (to copy
/// positions, texture coordinates and the like), the output normals and the renumbered
/// triangles.
pub fn split_by_normal(
    vertex_count: usize,
    triangles: &[[u32; 3]],
    normals: &[[[f32; 3]; 3]],
) -> (Vec<u32>, Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut source: Vec<u32> = (0..vertex_count as u32).collect();
    let mut out_normals = vec![[0.0, 0.0, 1.0]; vertex_count];
    let mut used = vec![false; vertex_count];
    let mut extra: std::collections::HashMap<(u32, [u32; 3]), u32> = std::collections::HashMap::new();
    // Equal normals are equal bit patterns once -0 is read as +0 (a cross product gives either).
    let bits = |n: [f32; 3]| n.map(|c| (c + 0.0).to_bits());
    let tris = triangles
        .iter()
        .zip(normals)
        .map(|(t, n3)| {
            std::array::from_fn(|k| {
                let (v, n) = (t[k], n3[k]);
                if !used[v as usize] {
                    used[v as usize] = true;
                    out_normals[v as usize] = n;
                    return v;
                }
                if bits(out_normals[v as usize]) == bits(n) {
                    return v;
                }
                *extra.entry((v, bits(n))).or_insert_with(|| {
                    source.push(v);
                    out_normals.push(n);
                    source.len() as u32 - 1
                })
            })
        })
        .collect();
    (source, out_normals, tris)
}

/// Corner normals from given per-vertex normals (already unit length, or NaN where the asset's
/// value was zero or not finite); a corner whose normal is unusable takes its triangle's face
/// normal. Returns the normals and how many corners were replaced.
pub fn given_corner_normals(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    given: &[[f32; 3]],
) -> (Vec<[[f32; 3]; 3]>, usize) {
    let flat = corner_normals(positions, triangles, Sharing::Flat);
    let mut replaced = 0;
    let out = triangles
        .iter()
        .zip(flat)
        .map(|(t, f)| {
            std::array::from_fn(|k| {
                let n = given[t[k] as usize];
                if n.iter().all(|c| c.is_finite()) {
                    n
                } else {
                    replaced += 1;
                    f[k]
                }
            })
        })
        .collect();
    (out, replaced)
}

/// A colour channel in [0, 1] (glTF: COLOR_0 floats are in range; clamped if not) as unorm16.
pub fn unorm16(v: f32) -> u16 {
    (v.clamp(0.0, 1.0) * 65535.0).round() as u16
}
