//! Geometry helpers shared by the importers: coordinate checks and normal generation.

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

/// Angle-weighted vertex normals (Thürmer and Wüthrich 1998) over the given triangles: each
/// triangle adds its unit normal weighted by its corner angle at the vertex. Vertices no
/// triangle reaches, or whose normal cancels out, get +Z.
pub fn angle_weighted_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut acc = vec![DVec3::ZERO; positions.len()];
    let p = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
    for t in triangles {
        let c = [p(t[0]), p(t[1]), p(t[2])];
        let n = (c[1] - c[0]).cross(c[2] - c[0]);
        let Some(n) = n.try_normalize() else { continue };
        for k in 0..3 {
            let e1 = c[(k + 1) % 3] - c[k];
            let e2 = c[(k + 2) % 3] - c[k];
            let angle = e1.angle_between(e2);
            if angle.is_finite() {
                acc[t[k] as usize] += n * angle;
            }
        }
    }
    acc.iter().map(|n| n.try_normalize().unwrap_or(DVec3::Z).as_vec3().to_array()).collect()
}
