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
