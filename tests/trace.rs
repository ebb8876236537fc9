//! The GPU traversal (`shaders/common/traverse.glsl`) against the CPU query of `kiln-format`
//! on the same rays: random, aimed, axis-aligned, at vertices and edges, grazing, from surfaces;
//! soups, shared-edge grids at 1e-3, 1e3 and 1e5 from the origin, slivers, coplanar overlaps, a
//! closed sphere, and the shared scenes. Closest hits must agree up to ties in distance; any-hit
//! answers exactly.
//!
//! Needs a Vulkan device; without one the tests say so and pass, unless `KILN_REQUIRE_VULKAN`
//! is set (as `.ci/run` does).

use std::time::Instant;

use glam::Vec3;
use kiln_compiler::raycheck::{Rng, generate};
use kiln_compiler::settings::Settings;
use kiln_format::query::{BvhQuery, IndexedTriangles, Ray, intersect_triangle};
use kiln_format::{Checksums, KilnFile, SceneView};
use kiln_player::session::Session;
use kiln_player::trace::{GpuRay, NO_HIT, RayQuery};
use kiln_test_support::{require, vulkan};
use kiln_tests::shapes::{height_grid, soup, sphere, transformed};
use kiln_tests::{Options, compile, scene_of, shared_scenes};

fn open(dir: &std::path::Path, bytes: &[u8]) -> Session {
    let file = dir.join("scene.kiln");
    std::fs::write(&file, bytes).unwrap();
    Session::open(&Options::new(file, 8, 8).unshadowed().rays().build(), Instant::now()).unwrap()
}

fn gpu_ray(r: &Ray) -> GpuRay {
    GpuRay { origin: r.origin.to_array(), tmin: r.tmin, direction: r.direction.to_array(), tmax: r.tmax }
}

/// Traces `rays` (generated over the compiled `bytes`) on both sides; returns the rays checked.
fn check(bytes: &[u8], rays: &[Ray], what: &str) -> usize {
    let file = KilnFile::from_bytes(bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let tris = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let cpu = BvhQuery::new(view.bvh, &tris);
    let dir = tempfile::tempdir().unwrap();
    let session = open(dir.path(), bytes);
    let bvh = session.scene.bvh.as_ref().expect("the BVH is resident");
    let mut query = RayQuery::new(&session.gpu).unwrap();
    let batch: Vec<GpuRay> = rays.iter().map(gpu_ray).collect();
    let (closest, _) = query.trace(&session.gpu, bvh, &batch, false).unwrap();
    let (any, _) = query.trace(&session.gpu, bvh, &batch, true).unwrap();
    drop(query);
    let (mut hits, mut ties) = (0, 0);
    for (i, ray) in rays.iter().enumerate() {
        let want = cpu.closest_hit(ray);
        let got = closest[i];
        match want {
            None => assert_eq!(got.t, NO_HIT, "{what}: ray {i} {ray:?}: GPU hit {got:?}, CPU none"),
            Some(w) => {
                assert!(got.t != NO_HIT, "{what}: ray {i} {ray:?}: GPU missed, CPU hit {w:?}");
                let tol = 1e-6 * w.t.abs().max(1e-30);
                assert!(
                    (got.t - w.t).abs() <= tol,
                    "{what}: ray {i} {ray:?}: GPU t {} vs CPU t {}",
                    got.t,
                    w.t
                );
                if got.triangle != w.triangle {
                    // A tie: the GPU's triangle must be hit at the same distance.
                    let other = intersect_triangle(ray, tris_corners(&view, got.triangle), f32::INFINITY)
                        .unwrap_or_else(|| {
                            panic!("{what}: ray {i}: GPU triangle {} is not hit at all", got.triangle)
                        });
                    assert!(
                        (other.t - w.t).abs() <= tol,
                        "{what}: ray {i}: GPU triangle {} at {} vs CPU {} at {}",
                        got.triangle,
                        other.t,
                        w.triangle,
                        w.t
                    );
                    ties += 1;
                }
                hits += 1;
            }
        }
        assert_eq!(any[i].t != NO_HIT, want.is_some(), "{what}: ray {i} {ray:?}: any-hit disagrees");
    }
    assert_eq!(session.close(), 0, "{what}: validation errors");
    eprintln!("{what}: {} rays, {hits} hits, {ties} ties", rays.len());
    rays.len()
}

fn tris_corners(view: &SceneView, t: u32) -> [Vec3; 3] {
    view.triangles[t as usize].map(|v| Vec3::from(view.vertices[v as usize].position))
}

fn geometry_only() -> Settings {
    Settings { shaft_variants: Some(0), ..Default::default() }
}

/// Compiles `tris` and checks `n` rays of every class.
fn check_shape(tris: &[[Vec3; 3]], n: u64, seed: u64, what: &str) {
    let bytes = compile(scene_of(tris), geometry_only());
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let t = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let (lo, hi) = (Vec3::from(view.manifest.bounds.min), Vec3::from(view.manifest.bounds.max));
    let rays: Vec<Ray> = generate(&t, lo, hi, n, seed).into_iter().map(|s| s.ray).collect();
    check(&bytes, &rays, what);
}

#[test]
fn gpu_traversal_equals_the_cpu_query_on_adversarial_shapes() {
    require!(vulkan());
    let mut rng = Rng::new(3);
    check_shape(&soup(&mut rng, 3000, 0.1), 6000, 1, "soup");
    let grid = height_grid(16, 0.2, &mut rng);
    for (scale, offset, what) in [
        (1.0, Vec3::ZERO, "grid"),
        (1e-3, Vec3::ZERO, "grid ×1e-3"),
        (1e3, Vec3::ZERO, "grid ×1e3"),
        (1.0, Vec3::splat(1e5), "grid at 1e5"),
    ] {
        check_shape(&transformed(&grid, scale, offset), 3000, 2, what);
    }
    let mut slivers = Vec::new();
    for i in 0..50 {
        let x = i as f32 * 0.02;
        slivers.push([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1e-6, 1.0, 0.0), Vec3::new(x, 1.0, 1e-7)]);
        let o = i as f32 * 0.01;
        slivers.push([Vec3::new(o, o, 0.5), Vec3::new(1.0, o, 0.5), Vec3::new(o, 1.0, 0.5)]);
    }
    check_shape(&slivers, 3000, 3, "slivers and coplanar overlaps");
}

#[test]
fn gpu_traversal_is_watertight_on_a_closed_sphere() {
    require!(vulkan());
    let tris = sphere(48, 24);
    let bytes = compile(scene_of(&tris), geometry_only());
    let centre = Vec3::new(1e-3, -2e-3, 3e-3);
    let mut targets: Vec<Vec3> =
        tris.iter().flat_map(|t| [t[0], (t[0] + t[1]) * 0.5, (t[1] + t[2]) * 0.5]).collect();
    let mut rng = Rng::new(9);
    targets.extend((0..5000).map(|_| rng.direction()));
    let rays: Vec<Ray> =
        targets.iter().map(|t| Ray::new(centre, (*t - centre).normalize(), 0.0, f32::INFINITY)).collect();
    // `check` requires the GPU to agree with the CPU, which hits on every one of these rays.
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let t = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let cpu = BvhQuery::new(view.bvh, &t);
    assert!(rays.iter().all(|r| cpu.closest_hit(r).is_some()));
    check(&bytes, &rays, "closed sphere");
}

#[test]
fn gpu_traversal_equals_the_cpu_query_on_the_shared_scenes() {
    require!(vulkan());
    let Some(scenes) = shared_scenes() else {
        return;
    };
    for name in ["cornell_box", "pica_pica"] {
        let scene = kiln_compiler::import::import(&scenes.join(name).join("scene.gltf")).unwrap();
        let bytes = compile(scene, Settings { shadow_res: 16, ..geometry_only() });
        let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
        let view = SceneView::new(&file).unwrap();
        let t = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
        let (lo, hi) = (Vec3::from(view.manifest.bounds.min), Vec3::from(view.manifest.bounds.max));
        let rays: Vec<Ray> = generate(&t, lo, hi, 20_000, 5).into_iter().map(|s| s.ray).collect();
        check(&bytes, &rays, name);
    }
}
