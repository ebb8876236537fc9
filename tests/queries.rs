//! Accelerated queries against brute force on random and adversarial triangle sets:
//! property tests over soups, shared-edge grids, slivers, coplanar overlaps, and scenes far
//! from the origin, tiny and huge; plus watertightness of closed meshes.

use glam::Vec3;
use kiln_compiler::raycheck::{Agreement, RaySample, Rng, compare, generate};
use kiln_compiler::settings::{BvhPreset, Settings};
use kiln_format::query::{BruteForce, BvhQuery, IndexedTriangles, Ray, closest_hit_brute_force};
use kiln_format::{Checksums, KilnFile, SceneView};
use kiln_tests::shapes::{height_grid, soup, sphere, transformed};
use kiln_tests::{compile, scene_of};
use proptest::prelude::*;

/// Settings that bake geometry and BVH only: these tests query the BVH, and baking line space
/// for every generated case made them several times slower.
fn geometry_only() -> Settings {
    Settings { shaft_variants: Some(0), ..Default::default() }
}

/// Compiles `tris`, then checks `rays` rays of every class: BVH against brute force.
fn check(tris: &[[Vec3; 3]], preset: BvhPreset, rays: u64, seed: u64) -> Result<(), String> {
    let bytes = compile(scene_of(tris), Settings { bvh_preset: preset, ..geometry_only() });
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).map_err(|e| e.to_string())?;
    let view = SceneView::new(&file).map_err(|e| e.to_string())?;
    let t = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let bvh = BvhQuery::new(view.bvh, &t);
    let brute = BruteForce::new(&t);
    let (lo, hi) = (Vec3::from(view.manifest.bounds.min), Vec3::from(view.manifest.bounds.max));
    let tol = 1e-6 * (hi - lo).length();
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
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn soups_match_brute_force(seed in any::<u64>(), n in 1usize..400, size in 0.01f32..1.0) {
        let mut rng = Rng::new(seed);
        let tris = soup(&mut rng, n, size);
        prop_assert_eq!(check(&tris, BvhPreset::Medium, 300, seed), Ok(()));
    }

    #[test]
    fn grids_match_brute_force_at_every_scale(seed in any::<u64>(), n in 1usize..24, which in 0usize..4) {
        let mut rng = Rng::new(seed);
        let (scale, offset) = [(1.0, Vec3::ZERO), (1e-3, Vec3::ZERO), (1e3, Vec3::ZERO), (1.0, Vec3::splat(1e5))][which];
        let tris = transformed(&height_grid(n, 0.2, &mut rng), scale, offset);
        prop_assert_eq!(check(&tris, BvhPreset::Fast, 300, seed), Ok(()));
    }
}

#[test]
fn every_preset_matches_brute_force() {
    let mut rng = Rng::new(7);
    let tris = soup(&mut rng, 3000, 0.1);
    for preset in [BvhPreset::Fast, BvhPreset::Medium, BvhPreset::Slow] {
        check(&tris, preset, 3000, 7).unwrap();
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
    check(&tris, BvhPreset::Medium, 5000, 3).unwrap();
}

#[test]
fn one_triangle_and_huge_triangle_scenes() {
    check(&[[Vec3::ZERO, Vec3::X, Vec3::Y]], BvhPreset::Medium, 2000, 1).unwrap();
    let mut rng = Rng::new(5);
    let mut tris = soup(&mut rng, 200, 0.05);
    tris.push([Vec3::new(-1e4, -1.0, -1e4), Vec3::new(1e4, -1.0, -1e4), Vec3::new(0.0, -1.0, 1e4)]);
    check(&tris, BvhPreset::Medium, 3000, 5).unwrap();
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
