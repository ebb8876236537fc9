//! Times one line-space bake of a row of seed 004's Table 1 (for profiling), and prints a digest
//! of its bits, records and candidate lists (to compare two builds' bakes):
//! `cargo run --release -p kiln-compiler --example prof_ls -- ROW VARIANT [RUNS]` (VARIANT:
//! pnmt, cand or binary). `KILN_PROF_KEEP=walls` keeps only the Cornell box's triangles in
//! the cells' lists, `object` only the object's. `KILN_PROF_GPU=1` bakes on the GPU (a CPU
//! implementation such as lavapipe too, where there is no GPU), `validate` with Vulkan's
//! validation layer.

use std::time::Instant;

use kiln_compiler::bake::linespace;
use kiln_compiler::bench_scenes::{BOX_TRIANGLES, TABLE1, attributes, cornell_with_object};
use kiln_format::linespace::{PnmtLayout, Variants};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let row: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(4);
    let variant = args.get(2).map(String::as_str).unwrap_or("pnmt");
    let runs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1);
    let row_config = TABLE1[row - 1];
    let (res, n) = (row_config.res, row_config.n);
    let variants = match variant {
        "cand" => Variants::BINARY | Variants::CANDIDATES,
        "binary" => Variants::BINARY,
        _ => Variants::BINARY | Variants::PNMT,
    };
    let scene = cornell_with_object(row_config.object, 42);
    let geometry = kiln_compiler::analyze::geometry::SceneGeometry::new(&scene);
    let attrs = attributes(&scene);
    let progress = kiln_compiler::progress::Progress::hidden();
    let gpu = std::env::var("KILN_PROF_GPU").ok().map(|v| {
        let options = kiln_gpubake::Options { allow_cpu: true, validate: v == "validate" };
        let gpu = linespace::gpu::GpuBaker::new(&options).expect("a Vulkan device");
        gpu.warm(n, PnmtLayout::CompactNoUv).expect("GPU buffers");
        println!("device: {}", gpu.device());
        gpu
    });
    let mut times = Vec::new();
    for _ in 0..runs {
        let mut voxels = geometry.voxels(res).clone();
        // KILN_PROF_KEEP=walls|object: only the box's triangles, or only the object's.
        if let Ok(keep) = std::env::var("KILN_PROF_KEEP") {
            let walls = keep == "walls";
            let (mut offsets, mut tris) = (vec![0u32], Vec::new());
            for w in voxels.offsets.windows(2) {
                tris.extend(
                    voxels.triangles[w[0] as usize..w[1] as usize]
                        .iter()
                        .filter(|&&t| (t < BOX_TRIANGLES) == walls),
                );
                offsets.push(tris.len() as u32);
            }
            voxels.offsets = offsets;
            voxels.triangles = tris;
        }
        let t = Instant::now();
        let ls = linespace::bake(
            gpu.as_ref(),
            &attrs,
            voxels,
            0.0,
            n,
            variants,
            PnmtLayout::CompactNoUv,
            None,
            &progress,
        )
        .expect("bake");
        times.push(t.elapsed().as_secs_f64() * 1e3);
        let counts: Vec<u32> = ls.voxel_offsets.windows(2).map(|w| w[1] - w[0]).filter(|&c| c > 0).collect();
        let mut sorted = counts.clone();
        sorted.sort_unstable();
        // A digest of the bits, records and lists, to compare bakes of two builds.
        let mut digest = 0xcbf2_9ce4_8422_2325u64;
        for w in ls.bits.iter().chain(&ls.pnmt).chain(&ls.candidates).chain(&ls.candidate_offsets) {
            digest = (digest ^ *w as u64).wrapping_mul(0x100_0000_01b3);
        }
        println!(
            "row {row} {variant}: {:.1} ms, digest {digest:016x}, tests {}, filled {}, cells {}, triangles a cell median {} mean {:.1} p90 {} max {}",
            times.last().unwrap(),
            ls.tests,
            ls.header.filled,
            counts.len(),
            sorted[sorted.len() / 2],
            counts.iter().sum::<u32>() as f64 / counts.len() as f64,
            sorted[sorted.len() * 9 / 10],
            sorted.last().unwrap()
        );
    }
    if let Some(gpu) = &gpu {
        println!("validation errors: {}", gpu.validation_errors());
    }
    times.sort_by(f64::total_cmp);
    println!("median {:.1} ms", times[times.len() / 2]);
}
