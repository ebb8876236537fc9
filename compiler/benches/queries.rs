//! Query throughput of every line-space variant against BVH traversal on the same rays, one
//! thread: closest hit (BVH, candidates, PNMT) and any hit (BVH, candidates, binary). Rays start
//! on random surface points in random directions of the outward hemisphere (diffuse bounce
//! rays, the line space's use), plus random rays through the scene.
//!
//! `cargo bench -p kiln-compiler --bench queries`

use std::time::Instant;

use glam::Vec3;
use kiln_compiler::bench_scenes::{BUNNY, TEAPOT, cornell_with_object};
use kiln_compiler::ir::Scene;
use kiln_compiler::raycheck::Rng;
use kiln_compiler::settings::{Settings, VoxelRes};
use kiln_format::linespace::{LineSpace, Variants};
use kiln_format::query::{BvhQuery, IndexedTriangles, Ray, TriangleSource};
use kiln_format::{Checksums, KilnFile, SceneView};

fn compile(scene: Scene, res: u32, n: u32) -> Vec<u8> {
    let settings = Settings {
        voxel_res: VoxelRes::Cells(res),
        shaft_res: Some(n),
        shaft_variants: Some(Variants::ALL),
        ..Default::default()
    };
    kiln_compiler::pipeline::compile_to_bytes(scene, settings, "bench").expect("bakes")
}

fn rays(tris: &IndexedTriangles, lo: Vec3, hi: Vec3, n: usize) -> Vec<(Ray, Option<Vec3>)> {
    let mut rng = Rng::new(7);
    (0..n)
        .map(|i| {
            if i % 4 == 3 {
                return (Ray::new(rng.in_box(lo, hi), rng.direction(), 0.0, f32::INFINITY), None);
            }
            let t = rng.below(tris.len());
            let c = tris.corners(t);
            let normal = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or(Vec3::Y);
            let mut d = rng.direction();
            if d.dot(normal) < 0.0 {
                d = -d;
            }
            // Offset along the normal by a relative epsilon (the player's rule for bounce rays).
            let o = rng.on_triangle(c) + normal * (1e-4 * (hi - lo).length());
            (Ray::new(o, d, 0.0, f32::INFINITY), Some(normal))
        })
        .collect()
}

fn rate(label: &str, rays: &[(Ray, Option<Vec3>)], mut f: impl FnMut(&Ray, Option<Vec3>) -> bool) -> f64 {
    let mut best = f64::INFINITY;
    let mut hits = 0;
    for _ in 0..3 {
        let t = Instant::now();
        hits = rays.iter().filter(|(r, n)| f(r, *n)).count();
        best = best.min(t.elapsed().as_secs_f64());
    }
    let mrays = rays.len() as f64 / best / 1e6;
    println!("    {label:<28} {mrays:>8.3} Mrays/s  ({:.1}% hit)", 100.0 * hits as f64 / rays.len() as f64);
    mrays
}

fn main() {
    let mut scenes: Vec<(String, Scene, u32)> = vec![
        ("box (32 tris), 8^3".into(), cornell_with_object(0, 42), 8),
        ("box + 15,704, 32^3".into(), cornell_with_object(TEAPOT, 42), 32),
        ("box + 69,451, 32^3".into(), cornell_with_object(BUNNY, 42), 32),
    ];
    let pica =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes/pica_pica/scene.gltf");
    if pica.is_file() {
        let mut s = kiln_compiler::import::import(&pica).expect("pica_pica imports");
        kiln_compiler::analyze::validate::finish(&mut s, "pica").expect("valid");
        scenes.push(("pica_pica (76,274), 24".into(), s, 24));
    } else {
        println!("pica_pica skipped: {} is absent", pica.display());
    }
    println!(
        "query throughput, 1 thread, best of 3, 200,000 rays (3/4 diffuse bounces from surfaces, 1/4 random), N = 4"
    );
    for (name, scene, res) in scenes {
        let bytes = compile(scene, res, 4);
        let file = KilnFile::from_bytes(&bytes, Checksums::Eager).expect("valid file");
        let view = SceneView::new(&file).expect("valid scene");
        let ls = LineSpace::new(&file, view.triangles.len(), view.materials.len())
            .expect("valid")
            .expect("line space");
        let t = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
        let bvh = BvhQuery::new(view.bvh, &t);
        let (lo, hi) = (Vec3::from(view.manifest.bounds.min), Vec3::from(view.manifest.bounds.max));
        let rs = rays(&t, lo, hi, 200_000);
        println!("  {name}: {} cells non-empty", ls.header.slots);
        let b = rate("BVH closest hit", &rs, |r, _| bvh.closest_hit(r).is_some());
        let c = rate("candidates closest hit", &rs, |r, _| ls.closest_hit(&t, r).is_some());
        let p = rate("PNMT approximate hit", &rs, |r, n| ls.pnmt_hit(r, n).is_some());
        let ba = rate("BVH any hit", &rs, |r, _| bvh.any_hit(r));
        let ca = rate("candidates any hit", &rs, |r, _| ls.any_hit(&t, r));
        let bin = rate("binary any hit (conservative)", &rs, |r, _| ls.any_hit_binary(r));
        println!(
            "    ratios to BVH closest: candidates {:.2}, PNMT {:.2}; to BVH any: candidates {:.2}, binary {:.2}",
            c / b,
            p / b,
            ca / ba,
            bin / ba
        );
    }
}
