//! The shaft index mapping: faces, patches, face pairs and the front/back convention. It is
//! specified in `FORMAT.md` ("Line space"), implemented here once, and mirrored by
//! `shaders/common/shaft.glsl` (a test runs both on a table of cases).
//!
//! - Faces of a voxel: 0 = −X, 1 = +X, 2 = −Y, 3 = +Y, 4 = −Z, 5 = +Z (axis = f / 2, side = f % 2).
//! - A face's patch coordinates (u, v) run along the two other axes in increasing axis order,
//!   each split into N cells: patch = iu · N + iv with iu = min(N − 1, ⌊N · u⌋).
//! - Unordered face pairs (a, b), a < b, are numbered 0..15 in lexicographic order.
//! - Shaft = pair · N⁴ + patch_a · N² + patch_b; 15 N⁴ shafts per voxel.
//! - A ray runs through a shaft *front to back* when it enters through face a (the lower face
//!   number) and leaves through face b; *back to front* otherwise.

/// Largest supported shaft resolution (15 · 8⁴ = 61,440 shafts per voxel).
pub const MAX_SHAFT_RES: u32 = 8;

/// Number of unordered face pairs.
pub const FACE_PAIRS: u32 = 15;

/// Shafts per voxel at resolution `n`.
pub const fn shafts_per_voxel(n: u32) -> u32 {
    FACE_PAIRS * n * n * n * n
}

/// Axis of a face.
pub const fn face_axis(face: u32) -> usize {
    (face / 2) as usize
}

/// The (u, v) axes of a face: the other two axes in increasing order.
pub const fn face_uv_axes(face: u32) -> (usize, usize) {
    match face / 2 {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// Number of the unordered pair (a, b), a < b, both in 0..6.
pub const fn pair_index(a: u32, b: u32) -> u32 {
    // Pairs before row a: 5 + 4 + ... = a·(11 − a)/2; then b − a − 1 within the row.
    a * (11 - a) / 2 + (b - a - 1)
}

/// The faces of pair `p` (inverse of [`pair_index`]).
pub const fn pair_faces(p: u32) -> (u32, u32) {
    let mut a = 0;
    let mut first = 0;
    while first + (5 - a) <= p {
        first += 5 - a;
        a += 1;
    }
    (a, a + 1 + (p - first))
}

/// Patch of the point with face coordinates (u, v) in [0, 1] (values outside are clamped).
pub fn patch_of(u: f64, v: f64, n: u32) -> u32 {
    let cell = |x: f64| ((x * n as f64).floor().max(0.0) as u32).min(n - 1);
    cell(u) * n + cell(v)
}

/// The shaft through entry (face, patch) and exit (face, patch), and whether it is traversed
/// front to back. `None` when both faces are the same (no volume: such a line only touches the
/// voxel along a face).
pub fn shaft(
    entry_face: u32,
    entry_patch: u32,
    exit_face: u32,
    exit_patch: u32,
    n: u32,
) -> Option<(u32, bool)> {
    let n2 = n * n;
    if entry_face == exit_face {
        return None;
    }
    let (a, pa, b, pb, front) = if entry_face < exit_face {
        (entry_face, entry_patch, exit_face, exit_patch, true)
    } else {
        (exit_face, exit_patch, entry_face, entry_patch, false)
    };
    Some((pair_index(a, b) * n2 * n2 + pa * n2 + pb, front))
}

/// The two faces and patches of a shaft number (inverse of [`shaft`], front orientation).
pub fn shaft_parts(shaft: u32, n: u32) -> (u32, u32, u32, u32) {
    let n2 = n * n;
    let (a, b) = pair_faces(shaft / (n2 * n2));
    let rest = shaft % (n2 * n2);
    (a, rest / n2, b, rest % n2)
}

/// Patch rectangle of `patch` on its face, in face coordinates: ((u0, v0), (u1, v1)).
pub fn patch_rect(patch: u32, n: u32) -> ((f64, f64), (f64, f64)) {
    let (iu, iv) = ((patch / n) as f64, (patch % n) as f64);
    let s = 1.0 / n as f64;
    ((iu * s, iv * s), ((iu + 1.0) * s, (iv + 1.0) * s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_round_trip_and_cover_0_to_15() {
        let mut seen = [false; 15];
        for a in 0..6 {
            for b in a + 1..6 {
                let p = pair_index(a, b);
                assert!(!seen[p as usize]);
                seen[p as usize] = true;
                assert_eq!(pair_faces(p), (a, b));
            }
        }
        assert!(seen.iter().all(|&s| s));
        assert_eq!(pair_index(0, 1), 0);
        assert_eq!(pair_index(4, 5), 14);
    }

    #[test]
    fn shafts_round_trip_for_every_resolution() {
        for n in 1..=MAX_SHAFT_RES {
            for s in 0..shafts_per_voxel(n) {
                let (a, pa, b, pb) = shaft_parts(s, n);
                assert_eq!(shaft(a, pa, b, pb, n), Some((s, true)));
                assert_eq!(shaft(b, pb, a, pa, n), Some((s, false)));
            }
        }
    }

    #[test]
    fn patches_clamp_at_the_far_edge() {
        assert_eq!(patch_of(1.0, 1.0, 4), 15);
        assert_eq!(patch_of(0.0, 0.0, 4), 0);
        assert_eq!(patch_of(-1e-9, 0.26, 4), 1);
        assert_eq!(patch_of(0.5, 0.0, 4), 8);
    }
}
