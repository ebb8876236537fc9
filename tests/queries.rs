//! Accelerated queries against brute force on random and adversarial triangle sets:
//! property tests over soups, shared-edge grids, slivers, coplanar overlaps, and scenes far
//! from the origin, tiny and huge; plus watertightness of closed meshes. Both the BVH and the
//! brute force are held to an exact reference (`kiln_tests::exact`, which shares no code with
//! `intersect_triangle`) wherever it decides, and lattice meshes aim rays exactly at edges and
//! vertices, where a `<` written as `<=` in the triangle test leaks.

use glam::Vec3;
use kiln_compiler::raycheck::{Agreement, RELATIVE_TOLERANCE, RaySample, Rng, compare, generate};
use kiln_compiler::settings::{BvhPreset, Settings};
use kiln_format::query::{
    BruteForce, BvhQuery, Hit, IndexedTriangles, Ray, TriangleSource, any_hit_brute_force,
    closest_hit_brute_force,
};
use kiln_format::{Checksums, KilnFile, SceneView};
use kiln_tests::exact::{self, Closest};
use kiln_tests::shapes::{
    corners_and_edge_points, height_grid, lattice_cube, lattice_octahedron, shuffled_corners, soup, sphere,
    transformed,
};
use kiln_tests::{compile, scene_of};
use proptest::prelude::*;

/// Settings that bake geometry and BVH only: these tests query the BVH, and baking line space
/// for every generated case made them several times slower.
fn geometry_only() -> Settings {
    Settings { shaft_variants: Some(0), ..Default::default() }
}

/// Compiles `tris`, then checks `rays` rays of every class: BVH against brute force, and both
/// against the exact reference where it decides. Returns how many rays it decided.
fn check(tris: &[[Vec3; 3]], preset: BvhPreset, rays: u64, seed: u64) -> Result<u64, String> {
    let bytes = compile(scene_of(tris), Settings { bvh_preset: preset, ..geometry_only() });
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).map_err(|e| e.to_string())?;
    let view = SceneView::new(&file).map_err(|e| e.to_string())?;
    let t = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let corners: Vec<[Vec3; 3]> = (0..t.len()).map(|i| t.corners(i)).collect();
    let bvh = BvhQuery::new(view.bvh, &t);
    let brute = BruteForce::new(&t);
    let (lo, hi) = (Vec3::from(view.manifest.bounds.min), Vec3::from(view.manifest.bounds.max));
    let tol = 1e-6 * (hi - lo).length();
    let mut decided = 0;
    for RaySample { class, ray, .. } in generate(&t, lo, hi, rays, seed) {
        let want = brute.closest_hit(&ray);
        // The prefiltered brute force agrees with the plain one.
        let plain = closest_hit_brute_force(&t, &ray);
        if want != plain {
            return Err(format!(
                "{class:?}: prefiltered brute force {want:?} vs plain {plain:?} for {ray:?}"
            ));
        }
        let got = bvh.closest_hit(&ray);
        if compare(got, want, tol) == Agreement::Mismatch {
            return Err(format!("{class:?} ray {ray:?}: BVH {got:?}, brute force {want:?}"));
        }
        if bvh.any_hit(&ray) != want.is_some() || brute.any_hit(&ray) != want.is_some() {
            return Err(format!("{class:?} ray {ray:?}: any-hit disagrees with closest hit {want:?}"));
        }
        let reference = exact::closest(
            ray.origin,
            ray.direction,
            ray.tmin,
            ray.tmax,
            corners.iter().copied(),
            f64::from(RELATIVE_TOLERANCE),
            f64::from(tol),
        );
        if reference != Closest::Undecided {
            decided += 1;
        }
        for (what, hit) in [("BVH", got), ("brute force", want)] {
            agrees_with_exact(&corners, &ray, hit, reference, f64::from(tol))
                .map_err(|e| format!("{class:?} ray {ray:?}: {what} {hit:?}: {e}"))?;
        }
    }
    Ok(decided)
}

/// Whether a closest hit agrees with the exact reference's: both miss, or the same distance
/// (within the tolerance of ties) on a triangle the ray truly meets.
fn agrees_with_exact(
    corners: &[[Vec3; 3]],
    ray: &Ray,
    hit: Option<Hit>,
    reference: Closest,
    tol: f64,
) -> Result<(), String> {
    let judged = hit
        .map(|h| exact::judge(ray.origin, ray.direction, ray.tmin, ray.tmax, corners[h.triangle as usize]));
    match (reference, hit, judged) {
        (Closest::Undecided, ..) | (Closest::Miss, None, _) => Ok(()),
        (Closest::Miss, Some(_), j) => {
            Err(format!("the exact reference misses; of that triangle it says {j:?}"))
        }
        (Closest::Hit { t, .. }, None, _) => Err(format!("the exact reference hits at t = {t}")),
        (Closest::Hit { t, reach }, Some(h), Some(j)) => {
            if (f64::from(h.t) - t).abs() > f64::from(RELATIVE_TOLERANCE) * t.abs() + tol + reach {
                Err(format!("the exact reference hits first at t = {t}; of that triangle it says {j:?}"))
            } else if !(j.closed_hit || j.near) {
                Err(format!("the exact reference says the ray misses that triangle: {j:?}"))
            } else {
                Ok(())
            }
        }
        (Closest::Hit { .. }, Some(_), None) => unreachable!("judged every hit"),
    }
}

/// Asserts that the exact reference decided at least an eighth of `rays`, so that the
/// comparison with it is not empty. Rays aimed at vertices and edges, grazing or starting on a
/// surface are mostly within rounding reach and undecided; soups decide about half their rays,
/// the flat one-triangle scene (whose ray origins hug its plane) and the slivers a quarter.
fn enough(decided: Result<u64, String>, rays: u64) -> Result<(), String> {
    let decided = decided?;
    if decided * 8 < rays {
        return Err(format!("the exact reference decided only {decided} of {rays} rays"));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn soups_match_brute_force(seed in any::<u64>(), n in 1usize..400, size in 0.01f32..1.0) {
        let mut rng = Rng::new(seed);
        let tris = soup(&mut rng, n, size);
        prop_assert_eq!(enough(check(&tris, BvhPreset::Medium, 300, seed), 300), Ok(()));
    }

    #[test]
    fn grids_match_brute_force_at_every_scale(seed in any::<u64>(), n in 1usize..24, which in 0usize..4) {
        let mut rng = Rng::new(seed);
        let (scale, offset) = [(1.0, Vec3::ZERO), (1e-3, Vec3::ZERO), (1e3, Vec3::ZERO), (1.0, Vec3::splat(1e5))][which];
        let tris = transformed(&height_grid(n, 0.2, &mut rng), scale, offset);
        prop_assert_eq!(enough(check(&tris, BvhPreset::Fast, 300, seed), 300), Ok(()));
    }
}

#[test]
fn every_preset_matches_brute_force() {
    let mut rng = Rng::new(7);
    let tris = soup(&mut rng, 3000, 0.1);
    for preset in [BvhPreset::Fast, BvhPreset::Medium, BvhPreset::Slow] {
        enough(check(&tris, preset, 3000, 7), 3000).unwrap();
    }
}

#[test]
fn slivers_and_coplanar_overlaps() {
    let mut tris = Vec::new();
    // Needle-thin slivers.
    for i in 0..50 {
        let x = i as f32 * 0.02;
        tris.push([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1e-6, 1.0, 0.0), Vec3::new(x, 1.0, 1e-7)]);
    }
    // Coplanar overlapping triangles in z = 0.5.
    for i in 0..50 {
        let o = i as f32 * 0.01;
        tris.push([Vec3::new(o, o, 0.5), Vec3::new(1.0, o, 0.5), Vec3::new(o, 1.0, 0.5)]);
    }
    enough(check(&tris, BvhPreset::Medium, 5000, 3), 5000).unwrap();
}

#[test]
fn one_triangle_and_huge_triangle_scenes() {
    enough(check(&[[Vec3::ZERO, Vec3::X, Vec3::Y]], BvhPreset::Medium, 2000, 1), 2000).unwrap();
    let mut rng = Rng::new(5);
    let mut tris = soup(&mut rng, 200, 0.05);
    tris.push([Vec3::new(-1e4, -1.0, -1e4), Vec3::new(1e4, -1.0, -1e4), Vec3::new(0.0, -1.0, 1e4)]);
    enough(check(&tris, BvhPreset::Medium, 3000, 5), 3000).unwrap();
}

/// A closed, finely tessellated sphere: rays from the centre must hit it, whichever way they
/// go, including straight at vertices and edges (a leak would be a miss).
#[test]
fn closed_mesh_is_watertight() {
    let tris = sphere(48, 24);
    let bytes = compile(scene_of(&tris), geometry_only());
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let t = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let bvh = BvhQuery::new(view.bvh, &t);
    let centre = Vec3::new(1e-3, -2e-3, 3e-3);
    let mut rng = Rng::new(11);
    let mut targets: Vec<Vec3> = view.vertices.iter().map(|v| Vec3::from(v.position)).collect();
    for tri in view.triangles {
        for k in 0..3 {
            let (a, b) =
                (view.vertices[tri[k] as usize].position, view.vertices[tri[(k + 1) % 3] as usize].position);
            targets.push((Vec3::from(a) + Vec3::from(b)) * 0.5);
        }
    }
    targets.extend((0..20000).map(|_| rng.direction()));
    for target in targets {
        let ray = Ray::new(centre, (target - centre).normalize(), 0.0, f32::INFINITY);
        assert!(bvh.closest_hit(&ray).is_some(), "ray towards {target:?} leaked out of the closed mesh");
    }
}

/// Closed lattice meshes (a cube, an octahedron) with their triangles' corners rotated and
/// reversed at random, so that each of the triangle test's three edge expressions sits on both
/// sides of many shared edges: rays from inside aimed exactly at every vertex and at points
/// along every edge must hit, through the BVH and both brute forces, at the distance the exact
/// reference gives (1: the target), on a triangle it says the ray meets. From the cube's centre
/// every direction's dominant coordinate is ±4, so the production test's shear is exact and its
/// edge values are exactly zero on edges: there a `<` slipped to `<=` rejects both triangles.
#[test]
fn lattice_meshes_are_watertight_at_edges_and_vertices() {
    let meshes = [
        ("cube", lattice_cube(4), [Vec3::ZERO, Vec3::new(0.5, -1.25, 0.75)]),
        ("octahedron", lattice_octahedron(8), [Vec3::ZERO, Vec3::new(-1.5, 0.25, 2.0)]),
    ];
    for (name, lattice, origins) in meshes {
        for seed in 0..2 {
            let tris = shuffled_corners(&lattice, &mut Rng::new(seed));
            let bytes = compile(scene_of(&tris), geometry_only());
            let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
            let view = SceneView::new(&file).unwrap();
            let t = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
            let corners: Vec<[Vec3; 3]> = (0..t.len()).map(|i| t.corners(i)).collect();
            let (bvh, brute) = (BvhQuery::new(view.bvh, &t), BruteForce::new(&t));
            for origin in origins {
                for target in corners_and_edge_points(&corners) {
                    let ray = Ray::new(origin, target - origin, 0.0, f32::INFINITY);
                    let at = format!("{name} (seed {seed}) from {origin} towards {target}");
                    let judged: Vec<_> = corners
                        .iter()
                        .map(|&c| exact::judge(ray.origin, ray.direction, 0.0, f32::INFINITY, c))
                        .collect();
                    // The reference itself: a closed mesh, seen from inside, is met exactly at the
                    // target, on the boundary of at least the two triangles sharing an edge.
                    let hits: Vec<_> = judged.iter().filter(|j| j.closed_hit).collect();
                    assert!(
                        hits.len() >= 2 && hits.iter().all(|j| j.on_boundary && (j.t - 1.0).abs() < 1e-12),
                        "{at}: the exact reference's hits {hits:?}"
                    );
                    for (what, hit) in [
                        ("BVH", bvh.closest_hit(&ray)),
                        ("brute force", brute.closest_hit(&ray)),
                        ("plain brute force", closest_hit_brute_force(&t, &ray)),
                    ] {
                        let h = hit.unwrap_or_else(|| panic!("{at}: {what} leaks (no hit)"));
                        let j = judged[h.triangle as usize];
                        assert!(
                            (h.t - 1.0).abs() <= 1e-6 && (j.closed_hit || j.near),
                            "{at}: {what} hits {h:?}; the exact reference says {j:?} of that triangle"
                        );
                    }
                    assert!(
                        bvh.any_hit(&ray) && brute.any_hit(&ray) && any_hit_brute_force(&t, &ray),
                        "{at}: any-hit leaks"
                    );
                }
            }
        }
    }
}

/// The subtree box of node `n` computed from its leaves' triangles, and every decoded child box
/// checked against its child's: returns the planes (node, slot, axis, by how much) that fall
/// inside. Decoding is written here: `p + 2^(e-127)·q` in f32, per FORMAT.md.
fn planes_inside(
    nodes: &[kiln_format::sections::CwbvhNode],
    corners: &[[Vec3; 3]],
    n: usize,
    bad: &mut Vec<String>,
) -> (Vec3, Vec3) {
    let node = &nodes[n];
    let mut all = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for slot in 0..8 {
        let meta = node.child_meta[slot];
        if meta == 0 {
            continue;
        }
        let (lo, hi) = if node.imask & (1 << slot) != 0 {
            let below = (node.imask as u32 & ((1u32 << slot) - 1)).count_ones();
            planes_inside(nodes, corners, (node.child_base_idx + below) as usize, bad)
        } else {
            let first = node.primitive_base_idx as usize + (meta & 0x1f) as usize;
            let count = (meta >> 5).count_ones() as usize;
            corners[first..first + count]
                .iter()
                .flatten()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)))
        };
        let q = |v: [[u8; 8]; 2], axis: usize| {
            let step = f32::from_bits((node.e[axis] as u32) << 23);
            (node.p[axis] + step * v[0][slot] as f32, node.p[axis] + step * v[1][slot] as f32)
        };
        let decoded = [
            q([node.child_min_x, node.child_max_x], 0),
            q([node.child_min_y, node.child_max_y], 1),
            q([node.child_min_z, node.child_max_z], 2),
        ];
        for (axis, (dlo, dhi)) in decoded.into_iter().enumerate() {
            if dlo > lo[axis] || dhi < hi[axis] {
                bad.push(format!(
                    "node {n} slot {slot} axis {axis}: decoded [{dlo}, {dhi}], exact [{}, {}]",
                    lo[axis], hi[axis]
                ));
            }
        }
        all = (all.0.min(lo), all.1.max(hi));
    }
    all
}

/// FORMAT.md: "quantisation rounds outwards, so the decoded boxes contain the exact ones", in f32
/// as every reader decodes them: on soups near and far from the origin, tiny and huge, and on the
/// shared scenes when they are here.
#[test]
fn decoded_child_boxes_contain_their_subtrees_exactly() {
    let mut files = Vec::new();
    let mut rng = Rng::new(11);
    for (i, (scale, offset)) in
        [(1.0f32, 0.0f32), (3.0, 1.0e4), (1e-3, -5.0e3), (100.0, 3.0e5), (0.5, 77.7)].into_iter().enumerate()
    {
        let tris =
            transformed(&soup(&mut rng, 3000, 0.05), scale, Vec3::new(offset, -0.5 * offset, 0.25 * offset));
        let preset = [BvhPreset::Fast, BvhPreset::Medium][i % 2];
        files.push((
            format!("soup {scale} at {offset}"),
            compile(scene_of(&tris), Settings { bvh_preset: preset, ..geometry_only() }),
        ));
    }
    if let Some(dir) = kiln_tests::shared_scenes() {
        for name in ["pica_pica", "cornell_box"] {
            let scene = kiln_compiler::import::import(&dir.join(name).join("scene.gltf")).unwrap();
            files.push((name.into(), compile(scene, geometry_only())));
        }
    }
    for (name, bytes) in files {
        let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
        let view = SceneView::new(&file).unwrap();
        let t = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
        let corners: Vec<[Vec3; 3]> = (0..t.len()).map(|i| t.corners(i)).collect();
        let mut bad = Vec::new();
        planes_inside(view.bvh, &corners, 0, &mut bad);
        assert!(
            bad.is_empty(),
            "{name}: {} planes inside their subtree, e.g. {:?}",
            bad.len(),
            &bad[..bad.len().min(3)]
        );
    }
}
