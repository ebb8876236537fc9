//! The line-space bake on a GPU (`linespace::gpu`, Vulkan compute) against the CPU bake, a
//! separate implementation of the same decisions in Rust: the same bits, ranks, PNMT records
//! and missing-record counts, word for word, for every shaft resolution, both record layouts the
//! GPU writes, binary alone, spanning walls, cells of hundreds of triangles, degenerate and tiny
//! triangles, and a scene far from the origin. Runs on any Vulkan device with 64-bit floats
//! (lavapipe on CI), with the validation layer where it is installed; without a device the
//! test says so and passes, unless `KILN_REQUIRE_VULKAN` is set (as `.ci/run` does).

use kiln_compiler::analyze::geometry::SceneGeometry;
use kiln_compiler::bake::linespace::{self, BakedLineSpace, gpu::GpuBaker};
use kiln_compiler::bench_scenes::{attributes, cornell_with_object};
use kiln_compiler::ir::Scene;
use kiln_compiler::progress::Progress;
use kiln_format::linespace::{PnmtLayout, Variants};
use kiln_format::sections::Vertex;
use kiln_test_support::{Need, require};

fn open() -> Option<GpuBaker> {
    let required = Need::Vulkan.required();
    let validate = GpuBaker::new(&kiln_gpubake::Options { allow_cpu: true, validate: true });
    let gpu = match validate {
        Ok(g) => Ok(g),
        // Without the validation layer (a developer's machine), unless CI requires everything.
        Err(e) if !required && e.contains("validation layer") => {
            GpuBaker::new(&kiln_gpubake::Options { allow_cpu: true, validate: false })
        }
        Err(e) => Err(e),
    };
    Need::Vulkan.check(gpu.map_err(|e| format!("no Vulkan device with 64-bit floats for the GPU bake ({e})")))
}

fn bake(
    gpu: Option<&GpuBaker>,
    scene: &Scene,
    res: u32,
    n: u32,
    variants: u32,
    layout: PnmtLayout,
) -> BakedLineSpace {
    let voxels = SceneGeometry::new(scene).voxels(res).clone();
    linespace::bake(gpu, &attributes(scene), voxels, 0.0, n, variants, layout, None, &Progress::hidden())
        .expect("bake")
}

/// The box with an object of `object` triangles, without texture coordinates (so that the GPU
/// also bakes full records), with a zero-area triangle and a tiny one inside the box.
fn scene(object: usize, seed: u64) -> Scene {
    let mut s = cornell_with_object(object, seed);
    s.uvs.clear();
    let base = s.vertices.len() as u32;
    for p in [
        [0.1, 0.5, 0.1],
        [0.3, 0.5, 0.1],
        [0.5, 0.5, 0.1],
        [-0.4, 1.2, 0.3],
        [-0.4 + 1e-6, 1.2, 0.3],
        [-0.4, 1.2 + 1e-6, 0.3],
    ] {
        s.vertices.push(Vertex { position: p, normal: [0.0, 0.0, 1.0] });
    }
    s.triangles.extend([[base, base + 1, base + 2], [base + 3, base + 4, base + 5]]);
    s.triangle_materials.extend([0, 1]);
    s
}

fn same(what: &str, cpu: &BakedLineSpace, gpu: &BakedLineSpace) {
    assert_eq!(cpu.header.filled, gpu.header.filled, "{what}: filled shafts");
    assert!(cpu.bits == gpu.bits, "{what}: bits differ");
    assert!(cpu.ranks == gpu.ranks, "{what}: ranks differ");
    let differing = cpu.pnmt.iter().zip(&gpu.pnmt).filter(|(a, b)| a != b).count();
    assert!(
        cpu.pnmt.len() == gpu.pnmt.len() && differing == 0,
        "{what}: {} against {} record words, {differing} differing",
        cpu.pnmt.len(),
        gpu.pnmt.len()
    );
    assert_eq!(cpu.pnmt_missing, gpu.pnmt_missing, "{what}: missing records");
    assert!(cpu.header.filled > 0, "{what}: nothing filled: the case tests nothing");
}

#[test]
fn gpu_bake_matches_the_cpu_bake() {
    let gpu = require!(open());
    let pnmt = Variants::BINARY | Variants::PNMT;
    // (scene, grid resolution, N, variants, layout): walls alone at the largest N; cells of a
    // few to hundreds of triangles; every N; binary alone; both layouts.
    let cases = [
        ("walls", scene(0, 1), 3, 8, pnmt, PnmtLayout::CompactNoUv),
        ("object, N 1", scene(400, 2), 4, 1, pnmt, PnmtLayout::Full),
        ("object, N 2", scene(400, 3), 5, 2, pnmt, PnmtLayout::CompactNoUv),
        ("object, N 3", scene(300, 4), 3, 3, Variants::BINARY, PnmtLayout::CompactNoUv),
        ("object, N 4", scene(600, 5), 2, 4, pnmt, PnmtLayout::Full),
        ("object, N 5", scene(200, 6), 4, 5, pnmt, PnmtLayout::CompactNoUv),
        ("object, N 6", scene(100, 7), 3, 6, pnmt, PnmtLayout::Full),
        ("object, N 7", scene(60, 8), 2, 7, pnmt, PnmtLayout::CompactNoUv),
    ];
    for (name, s, res, n, variants, layout) in &cases {
        let cpu = bake(None, s, *res, *n, *variants, *layout);
        let on_gpu = bake(Some(&gpu), s, *res, *n, *variants, *layout);
        same(name, &cpu, &on_gpu);
    }
    // Far from the origin: world coordinates of 10⁵ (single-precision steps of 1/128).
    let mut far = scene(200, 9);
    for v in &mut far.vertices {
        v.position = [v.position[0] + 1e5, v.position[1] - 1e5, v.position[2] + 5e4];
    }
    let cpu = bake(None, &far, 4, 4, pnmt, PnmtLayout::Full);
    same("far from the origin", &cpu, &bake(Some(&gpu), &far, 4, 4, pnmt, PnmtLayout::Full));
    assert_eq!(gpu.validation_errors(), 0, "Vulkan validation errors");
}
