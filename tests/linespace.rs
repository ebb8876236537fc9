//! The voxel grid and line space against brute force: random soups at every grid and shaft
//! resolution, scenes far from the origin, tiny and huge, slivers, coplanar overlaps, triangles
//! lying exactly on cell faces, edges and corners, one-cell and one-triangle scenes; and the
//! validation of damaged line-space sections.

use glam::Vec3;
use kiln_compiler::raycheck::{Rng, check_line_space};
use kiln_compiler::settings::{PnmtRecords, Settings, VoxelRes};
use kiln_format::linespace::{LineSpace, PnmtLayout, Variants};
use kiln_format::{Checksums, ContentHash, FileWriter, KilnFile, SceneView, sections};
use kiln_tests::shapes::{height_grid, soup};
use kiln_tests::{compile, rewrite, scene_of};
use proptest::prelude::*;

fn settings(res: u32, n: u32) -> Settings {
    Settings {
        voxel_res: VoxelRes::Cells(res),
        shaft_res: Some(n),
        shaft_variants: Some(Variants::ALL),
        ..Default::default()
    }
}

/// Compiles `tris` with every variant and checks `rays` rays: exact candidates, no binary false
/// misses. Returns the PNMT disagreement count for information.
fn check(tris: &[[Vec3; 3]], res: u32, n: u32, rays: u64, seed: u64) -> Result<u64, String> {
    let bytes = compile(scene_of(tris), settings(res, n));
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).map_err(|e| e.to_string())?;
    let view = SceneView::new(&file).map_err(|e| e.to_string())?;
    let ls = LineSpace::new(&file, view.triangles.len(), view.materials.len())
        .map_err(|e| e.to_string())?
        .ok_or("no line space")?;
    let c = check_line_space(&view, &ls, rays, seed);
    let cand = c.candidates.as_ref().ok_or("no candidates")?;
    if cand.mismatches != 0 || cand.any_hit_mismatches != 0 {
        return Err(format!(
            "{} candidate mismatches, {} any-hit: {:?}",
            cand.mismatches, cand.any_hit_mismatches, cand.examples
        ));
    }
    if c.binary.false_misses != 0 {
        return Err(format!("{} binary false misses: {:?}", c.binary.false_misses, c.binary.examples));
    }
    Ok(c.pnmt.map_or(0, |p| p.hit_disagreements))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20))]

    #[test]
    fn soups_at_every_resolution(seed in any::<u64>(), n in 1usize..150, size in 0.02f32..1.5, res in 1u32..10, shaft in 1u32..=6) {
        let mut rng = Rng::new(seed);
        let tris = soup(&mut rng, n, size);
        prop_assert!(check(&tris, res, shaft, 400, seed).is_ok(), "{:?}", check(&tris, res, shaft, 400, seed));
    }
}

#[test]
fn far_tiny_and_huge_scenes() {
    let mut rng = Rng::new(3);
    let base = height_grid(12, 0.3, &mut rng);
    for (scale, offset) in [
        (1.0, Vec3::ZERO),
        (1e-3, Vec3::ZERO),
        (1e3, Vec3::ZERO),
        (1.0, Vec3::splat(1e5)),
        (1e3, Vec3::new(1e5, -1e5, 3e4)),
    ] {
        let tris: Vec<[Vec3; 3]> = base.iter().map(|t| t.map(|p| p * scale + offset)).collect();
        check(&tris, 6, 4, 3000, 1).unwrap_or_else(|e| panic!("scale {scale}, offset {offset}: {e}"));
    }
}

#[test]
fn slivers_and_coplanar_overlaps() {
    let mut tris = Vec::new();
    for i in 0..40 {
        let x = i as f32 * 0.025;
        tris.push([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1e-6, 1.0, 0.0), Vec3::new(x, 1.0, 1e-7)]);
    }
    for i in 0..40 {
        let o = i as f32 * 0.01;
        tris.push([Vec3::new(o, o, 0.5), Vec3::new(1.0, o, 0.5), Vec3::new(o, 1.0, 0.5)]);
    }
    check(&tris, 5, 4, 4000, 2).unwrap();
}

/// Triangles lying exactly (to f32) in cell planes, along cell edges and through cell corners.
#[test]
fn triangles_on_cell_faces_edges_and_corners() {
    // A frame fixing the bounds to [0, 4]³, then the grid it gets at 4 cells.
    let frame = vec![
        [Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 4.0, 4.0)],
        [Vec3::splat(4.0), Vec3::new(4.0, 0.0, 4.0), Vec3::new(0.0, 4.0, 0.0)],
    ];
    let bounds = kiln_format::manifest::Bounds { min: [0.0; 3], max: [4.0; 3] };
    let g = kiln_compiler::bake::linespace::voxelize::grid(&bounds, 4);
    let plane = |k: f64| (g.origin[0] + k * g.cell) as f32;
    let mut tris = frame;
    for k in 1..4 {
        let (x, y) = (plane(k as f64), (g.origin[1] + k as f64 * g.cell) as f32);
        // In the plane x = x_k, and along the edge x = x_k, y = y_k, and through a corner.
        tris.push([Vec3::new(x, 0.5, 0.5), Vec3::new(x, 3.5, 0.5), Vec3::new(x, 0.5, 3.5)]);
        tris.push([Vec3::new(x, y, 0.2), Vec3::new(x, y, 3.8), Vec3::new(x + 0.5, y + 0.5, 2.0)]);
        let z = (g.origin[2] + k as f64 * g.cell) as f32;
        tris.push([Vec3::new(x, y, z), Vec3::new(x + 0.3, y, z + 0.2), Vec3::new(x, y + 0.3, z - 0.2)]);
    }
    check(&tris, 4, 3, 6000, 4).unwrap();
    check(&tris, 4, 1, 3000, 5).unwrap();
}

#[test]
fn one_cell_one_triangle_and_extreme_shaft_resolutions() {
    let tri = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
    for n in [1, 2, 8] {
        check(&tri, 1, n, 2000, n as u64).unwrap();
    }
    let mut rng = Rng::new(9);
    let tris = soup(&mut rng, 60, 0.6);
    check(&tris, 1, 8, 2000, 6).unwrap();
    check(&tris, 3, 1, 2000, 7).unwrap();
    check(&tris, 3, 8, 2000, 8).unwrap();
}

#[test]
fn damaged_line_space_sections_are_refused() {
    let mut rng = Rng::new(1);
    let bytes = compile(scene_of(&soup(&mut rng, 40, 0.5)), settings(3, 3));
    let refused = |b: &[u8]| {
        let f = KilnFile::from_bytes(b, Checksums::Eager).unwrap();
        let v = SceneView::new(&f).unwrap();
        LineSpace::new(&f, v.triangles.len(), v.materials.len()).expect_err("damage accepted").to_string()
    };
    let set_u32 = |d: &mut Vec<u8>, i: usize, v: u32| d[4 * i..4 * i + 4].copy_from_slice(&v.to_le_bytes());
    // A bit flipped in the shaft bits breaks the ranks.
    let msg = refused(&rewrite(&bytes, sections::SHAFT_BITS, |d| d[0] ^= 0x10));
    assert!(msg.contains("rank") || msg.contains("filled"), "{msg}");
    // A slot out of order.
    let msg = refused(&rewrite(&bytes, sections::SHAFT_SLOTS, |d| {
        let i = (0..d.len() / 4).find(|&i| d[4 * i..4 * i + 4] != [0xff; 4]).unwrap();
        set_u32(d, i, 7777)
    }));
    assert!(msg.contains("slot"), "{msg}");
    // A candidate entry naming a triangle beyond its cell.
    let msg = refused(&rewrite(&bytes, sections::CANDIDATES, |d| set_u32(d, 0, 0xffff)));
    assert!(msg.contains("candidate entry"), "{msg}");
    // A PNMT record naming a missing material: the compact record's material bits 0..10 are
    // bits 22..32 of its second word.
    assert_eq!(with_line_space(&bytes, |_, ls| ls.pnmt_layout), PnmtLayout::CompactNoUv);
    let msg = refused(&rewrite(&bytes, sections::PNMT, |d| {
        let w = u32::from_le_bytes(d[4..8].try_into().unwrap());
        set_u32(d, 1, w & 0x3f_ffff | 77 << 22)
    }));
    assert!(msg.contains("material 77"), "{msg}");
    // An undefined record layout (VGRD byte 84), and records one word short of the layout's.
    let msg = refused(&rewrite(&bytes, sections::GRID, |d| d[84] = 3));
    assert!(msg.contains("layout 3"), "{msg}");
    let msg = refused(&rewrite(&bytes, sections::PNMT, |d| d.truncate(d.len() - 4)));
    assert!(msg.contains("PNMT"), "{msg}");
    // Compact records in a version-1 (format 1.2) PNMT section, which holds full ones only.
    let f = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let mut w = FileWriter::new();
    for s in f.sections() {
        let version = if s.entry.kind == sections::PNMT { 1 } else { s.entry.version };
        let data = f.section_bytes(s).unwrap().into_owned();
        w.raw(s.entry.kind, s.entry.index, version, data, ContentHash::default()).unwrap();
    }
    let msg = refused(&w.to_bytes().unwrap());
    assert!(msg.contains("version-1"), "{msg}");
    // A voxel triangle out of range.
    let msg = refused(&rewrite(&bytes, sections::VOXEL_TRIANGLES, |d| set_u32(d, 0, 1_000_000)));
    assert!(msg.contains("triangle numbers"), "{msg}");
    // A section the header does not announce.
    let no_pnmt = compile(
        scene_of(&soup(&mut Rng::new(1), 40, 0.5)),
        Settings { shaft_variants: Some(Variants::BINARY), ..settings(3, 3) },
    );
    let f = KilnFile::from_bytes(&no_pnmt, Checksums::Eager).unwrap();
    let mut w = FileWriter::new();
    for s in f.sections() {
        w.raw(
            s.entry.kind,
            s.entry.index,
            s.entry.version,
            f.section_bytes(s).unwrap().into_owned(),
            ContentHash::default(),
        )
        .unwrap();
    }
    w.raw(sections::PNMT, 0, 1, vec![0u8; 32], ContentHash::default()).unwrap();
    let msg = refused(&w.to_bytes().unwrap());
    assert!(msg.contains("PNMT"), "{msg}");
}

/// Calls `f` with the scene and line space of a compiled file.
fn with_line_space<R>(bytes: &[u8], f: impl FnOnce(&SceneView, &LineSpace) -> R) -> R {
    let file = KilnFile::from_bytes(bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let ls = LineSpace::new(&file, view.triangles.len(), view.materials.len()).unwrap().unwrap();
    f(&view, &ls)
}

/// The grid sections of a compile of `tris` with `variants`: (bits, ranks, PNMT records).
fn shafts_of(tris: &[[Vec3; 3]], res: u32, n: u32, variants: u32) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let bytes = compile(scene_of(tris), Settings { shaft_variants: Some(variants), ..settings(res, n) });
    with_line_space(&bytes, |view, ls| {
        let c = check_line_space(view, ls, 2000, 9);
        assert_eq!(c.binary.false_misses, 0, "{:?}", c.binary.examples);
        (ls.bits.to_vec(), ls.ranks.to_vec(), ls.pnmt.to_vec())
    })
}

/// Without candidates, cells of many triangles keep only the union of their shafts and skip
/// the exact tests that cannot change it: the bits and records must be those of the bake with
/// candidates, which tests every triangle against every shaft it may reach. Dense soups (a few
/// hundred triangles a cell), near the origin and far from it.
#[test]
fn pnmt_without_candidates_equals_pnmt_with_them() {
    for offset in [Vec3::ZERO, Vec3::new(3e4, -2e4, 1e4)] {
        let tris: Vec<[Vec3; 3]> =
            soup(&mut Rng::new(17), 700, 0.4).iter().map(|t| t.map(|p| p + offset)).collect();
        for (res, n) in [(2, 4), (3, 3)] {
            let alone = shafts_of(&tris, res, n, Variants::BINARY | Variants::PNMT);
            let with = shafts_of(&tris, res, n, Variants::BINARY | Variants::CANDIDATES | Variants::PNMT);
            assert!(alone == with, "offset {offset}, {res} cells, N {n}: the two bakes differ");
        }
    }
}

/// A grid of thousands of occupied cells, which the bake lays out a chunk of cells at a time:
/// every PNMT record must lie on a triangle of its own cell's list (within the margin by which
/// a fallback point is clamped and the records' quantisation), which a record placed in
/// another cell's run breaks; the candidates' exactness checks their offsets.
#[test]
fn records_lie_on_their_cells_triangles_across_chunks() {
    let tris = height_grid(40, 0.3, &mut Rng::new(23));
    let bytes = compile(scene_of(&tris), settings(72, 2));
    with_line_space(&bytes, records_lie_on_their_cells_triangles);
}

/// The check of [`records_lie_on_their_cells_triangles_across_chunks`] on one file.
fn records_lie_on_their_cells_triangles(view: &SceneView, ls: &LineSpace) {
    let h = ls.header;
    let occupied = ls.slots.iter().filter(|&&s| s != u32::MAX).count();
    assert!(occupied > 3000, "{occupied} occupied cells: too few for several chunks");
    let c = check_line_space(view, ls, 1000, 4);
    assert_eq!(c.candidates.as_ref().map(|c| c.mismatches), Some(0));
    let tolerance = 2.0 * h.margin + (1e-4 + quantisation(ls)) * h.cell;
    let mut rank = 0usize;
    for (cell, &slot) in ls.slots.iter().enumerate() {
        if slot == u32::MAX {
            continue;
        }
        let filled: u32 = ls.bits[slot as usize * ls.words_per_slot..][..ls.words_per_slot]
            .iter()
            .map(|w| w.count_ones())
            .sum();
        let cell_min = h.cell_min(h.cell_coords(cell));
        for r in rank..rank + filled as usize {
            for back in [false, true] {
                let Some(hit) = ls.pnmt_layout.decode(ls.record(r, back), cell_min, h.cell) else { continue };
                let nearest = ls
                    .cell_triangles(cell)
                    .iter()
                    .map(|&t| distance_to_triangle(hit.position, [0, 1, 2].map(|k| corner(view, t, k))))
                    .fold(f64::INFINITY, f64::min);
                assert!(nearest <= tolerance, "cell {cell}, filled shaft {r}: {nearest} from its triangles");
            }
        }
        rank += filled as usize;
    }
    assert_eq!(rank as u64, h.filled);
}

/// How far (cell units) a record's quantised position may lie from the point it stands for:
/// half a step on each axis, from the layout's step count as FORMAT.md gives it.
fn quantisation(ls: &LineSpace) -> f64 {
    let steps = match ls.pnmt_layout {
        PnmtLayout::Full => 65535.0,
        PnmtLayout::Compact | PnmtLayout::CompactNoUv => 1023.0,
    };
    0.5 * 3f64.sqrt() / steps
}

/// Corner `k` of triangle `t` of the scene, in double precision.
fn corner(view: &SceneView, t: u32, k: usize) -> glam::DVec3 {
    let p = view.vertices[view.triangles[t as usize][k] as usize].position;
    glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

/// Distance from `p` to the triangle `t`: to its plane where the projection falls inside,
/// else to the nearest edge.
fn distance_to_triangle(p: glam::DVec3, t: [glam::DVec3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let inside = (0..3).all(|k| (t[(k + 1) % 3] - t[k]).cross(p - t[k]).dot(n) >= 0.0);
    if inside && n.length_squared() > 0.0 {
        return (p - t[0]).dot(n).abs() / n.length();
    }
    (0..3)
        .map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let s = ((p - a).dot(b - a) / (b - a).length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            (p - (a + (b - a) * s)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Every PNMT record against its shaft's own midpoint segment and candidate list (whose
/// exactness `check_line_space` checks): where the segment clearly crosses listed triangles,
/// the front (back) record is the crossing nearest the front (back) patch; where it clearly
/// misses them all, the record is the listed triangles' point (clipped to the widened cell)
/// reaching furthest towards that end along the pair's key. Shafts within rounding of either
/// case are skipped; both cases must be checked hundreds of times.
#[test]
fn records_are_nearest_segment_crossings_or_the_furthest_reaching_points() {
    let tris = soup(&mut Rng::new(41), 40, 0.7);
    for (records, layout) in
        [(PnmtRecords::Full, PnmtLayout::Full), (PnmtRecords::Compact, PnmtLayout::CompactNoUv)]
    {
        let bytes = compile(scene_of(&tris), Settings { pnmt_records: records, ..settings(3, 3) });
        let (hits, fallbacks) = with_line_space(&bytes, |view, ls| {
            assert_eq!(ls.pnmt_layout, layout, "an untextured scene's records");
            let c = check_line_space(view, ls, 2000, 5);
            assert_eq!(c.candidates.as_ref().map(|c| c.mismatches), Some(0));
            check_records(view, ls)
        });
        assert!(
            hits > 500 && fallbacks > 500,
            "{layout:?}: {hits} crossings and {fallbacks} fallbacks checked: too few"
        );
    }
}

/// The check of [`records_are_nearest_segment_crossings_or_the_furthest_reaching_points`]:
/// (records checked as crossings, records checked as fallbacks).
fn check_records(view: &SceneView, ls: &LineSpace) -> (u64, u64) {
    use glam::DVec3;
    let h = ls.header;
    let n = h.shaft_res;
    let m = h.margin / h.cell;
    let q = quantisation(ls);
    // Cell-local point of a face's patch centre.
    let centre = |face: u32, patch: u32| {
        let mut p = DVec3::ZERO;
        p[(face / 2) as usize] = (face % 2) as f64;
        let (ua, va) = if face < 2 {
            (1, 2)
        } else if face < 4 {
            (0, 2)
        } else {
            (0, 1)
        };
        p[ua] = ((patch / n) as f64 + 0.5) / n as f64;
        p[va] = ((patch % n) as f64 + 0.5) / n as f64;
        p
    };
    let outward = |face: u32| {
        let mut d = DVec3::ZERO;
        d[(face / 2) as usize] = if face.is_multiple_of(2) { -1.0 } else { 1.0 };
        d
    };
    let (mut hits, mut fallbacks) = (0u64, 0u64);
    for (cell, &slot) in ls.slots.iter().enumerate() {
        if slot == u32::MAX {
            continue;
        }
        let cell_min = h.cell_min(h.cell_coords(cell));
        let local = |p: DVec3| (p - cell_min) / h.cell;
        let list = ls.cell_triangles(cell);
        for shaft in 0..15 * n.pow(4) {
            let Some(rank) = ls.rank(slot, shaft) else { continue };
            let n2 = n * n;
            let pair = shaft / (n2 * n2);
            let (fa, fb) =
                (0..6u32).flat_map(|a| (a + 1..6).map(move |b| (a, b))).nth(pair as usize).unwrap();
            let (pa, pb) = ((shaft % (n2 * n2)) / n2, shaft % n2);
            let (o, e) = (centre(fa, pa), centre(fb, pb));
            let w = outward(fb) - outward(fa);
            let listed: Vec<[DVec3; 3]> = ls
                .entries(rank)
                .iter()
                .map(|&en| {
                    let t = list[kiln_format::linespace::entry::local(en) as usize];
                    [0, 1, 2].map(|k| local(corner(view, t, k)))
                })
                .collect();
            let crossings: Vec<Option<f64>> = listed.iter().map(|&t| crossing(o, e, t)).collect();
            let decoded = [false, true].map(|back| {
                ls.pnmt_layout.decode(ls.record(rank, back), cell_min, h.cell).map(|x| local(x.position))
            });
            if crossings.iter().all(|c| c.is_some_and(|t| t.is_finite())) && !crossings.is_empty() {
                // Every listed triangle clearly crossed or clearly missed.
                let mut ts: Vec<f64> = crossings.iter().filter_map(|c| c.filter(|t| *t >= 0.0)).collect();
                if ts.is_empty() {
                    // Clearly missed by all: the fallback.
                    let keys = listed.iter().filter_map(|&t| {
                        let poly = clip_to_cube(t, m);
                        let k = poly.iter().map(|p| p.dot(w));
                        (!poly.is_empty()).then(|| {
                            (k.clone().fold(f64::INFINITY, f64::min), k.fold(f64::NEG_INFINITY, f64::max))
                        })
                    });
                    let (lo, hi) =
                        keys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (x, y)| (a.min(x), b.max(y)));
                    let tolerance = 2.0 * m + 1e-3 + q;
                    let (Some(front), Some(back)) = (decoded[0], decoded[1]) else {
                        panic!("cell {cell} shaft {shaft}: a fallback record is missing")
                    };
                    assert!(
                        (front.dot(w) - lo).abs() <= tolerance,
                        "cell {cell} shaft {shaft}: front key {} not {lo}",
                        front.dot(w)
                    );
                    assert!(
                        (back.dot(w) - hi).abs() <= tolerance,
                        "cell {cell} shaft {shaft}: back key {} not {hi}",
                        back.dot(w)
                    );
                    fallbacks += 2;
                } else {
                    ts.sort_by(f64::total_cmp);
                    let distinct = |a: f64, b: f64| (a - b).abs() > 0.01;
                    let (first, last) = (ts[0], ts[ts.len() - 1]);
                    let ends = [
                        (first, ts.get(1).is_none_or(|&t| distinct(t, first))),
                        (last, ts.len() < 2 || distinct(ts[ts.len() - 2], last)),
                    ];
                    for (k, (t, clear)) in ends.into_iter().enumerate() {
                        if !clear {
                            continue;
                        }
                        let want = o + (e - o) * t;
                        let got = decoded[k]
                            .unwrap_or_else(|| panic!("cell {cell} shaft {shaft}: record {k} missing"));
                        assert!(
                            (got - want).length() <= 1e-3 + q,
                            "cell {cell} shaft {shaft} end {k}: {got} not {want}"
                        );
                        hits += 1;
                    }
                }
            }
        }
    }
    (hits, fallbacks)
}

/// Where the segment o → e crosses the triangle t: `Some(t ∈ [0, 1])` clearly inside, `Some(−1)`
/// clearly outside, `Some(NaN)` (or `None` for a degenerate triangle) within 1e-6 of either.
fn crossing(o: glam::DVec3, e: glam::DVec3, t: [glam::DVec3; 3]) -> Option<f64> {
    const NEAR: f64 = 1e-6;
    let d = e - o;
    let nrm = (t[1] - t[0]).cross(t[2] - t[0]);
    let len = nrm.length();
    if len < 1e-9 {
        return None;
    }
    let denom = nrm.dot(d);
    if denom.abs() < 1e-9 * len {
        // Parallel to the plane: clearly outside unless within reach of it.
        let dist = nrm.dot(o - t[0]).abs() / len;
        return Some(if dist > NEAR { -1.0 } else { f64::NAN });
    }
    let s = nrm.dot(t[0] - o) / denom;
    let p = o + d * s;
    // Signed distances of p from the edges, within the plane.
    let edge = (0..3)
        .map(|k| (t[(k + 1) % 3] - t[k]).cross(p - t[k]).dot(nrm) / (len * (t[(k + 1) % 3] - t[k]).length()))
        .fold(f64::INFINITY, f64::min);
    let reach = NEAR * d.length() / (denom.abs() / len);
    if !(-NEAR..=1.0 + NEAR).contains(&s) || edge < -reach - NEAR {
        return Some(-1.0);
    }
    if !(NEAR..=1.0 - NEAR).contains(&s) || edge < reach + NEAR {
        return Some(f64::NAN);
    }
    Some(s)
}

/// The triangle t clipped to the cube [−m, 1 + m]³ (Sutherland–Hodgman, one plane at a time).
fn clip_to_cube(t: [glam::DVec3; 3], m: f64) -> Vec<glam::DVec3> {
    let mut poly = t.to_vec();
    for axis in 0..3 {
        for (bound, keep_below) in [(-m, false), (1.0 + m, true)] {
            let inside = |p: &glam::DVec3| if keep_below { p[axis] <= bound } else { p[axis] >= bound };
            let mut out = Vec::new();
            for (i, &p) in poly.iter().enumerate() {
                let q = poly[(i + 1) % poly.len()];
                if inside(&p) {
                    out.push(p);
                }
                if inside(&p) != inside(&q) {
                    out.push(p + (q - p) * ((bound - p[axis]) / (q[axis] - p[axis])));
                }
            }
            poly = out;
        }
    }
    poly
}
