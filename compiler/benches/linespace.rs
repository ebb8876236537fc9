//! Voxel grid and line-space bake time and memory for the configurations of seed 004's Table 1,
//! with PNMT and with candidates, against the thesis's GTX 1080 times; and the plan's size
//! estimate (`analyze::budget`: central, and the two-standard-error bound the budget uses)
//! against the baked bytes of the grid and each variant.
//!
//! PNMT is timed with the records the compiler stores for these untextured scenes by default
//! (compact, without uv: 8 bytes); one more bake with full 16-byte records gives their time and
//! the compact records' error against them, record by record.
//!
//! `cargo bench -p kiln-compiler --bench linespace [-- ROWS]` (ROWS: comma-separated row numbers,
//! default all; KILN_BENCH_RUNS: runs per row, default 3). With `KILN_BENCH_GPU=1` the binary
//! and PNMT bakes run where `kiln compile --line-space-device auto` runs them: on the GPU
//! (`linespace::gpu`) from `AUTO_MIN_WORK` triangle-shafts, else on the CPU (the candidate bakes
//! stay on the CPU); each row's PNMT bits and records are then compared with a CPU bake's, word
//! for word. `KILN_BENCH_GPU=all` puts every row on the GPU.

use std::time::Instant;

use kiln_compiler::analyze::budget::Estimate;
use kiln_compiler::bake::linespace;
use kiln_compiler::bench_scenes::{TABLE1, attributes, cornell_with_object};
use kiln_compiler::ir::Scene;
use kiln_format::linespace::{PnmtLayout, Variants};

#[path = "../tests/util/held.rs"]
mod held;

/// The records the compiler stores for an untextured scene by default.
const COMPACT: PnmtLayout = PnmtLayout::CompactNoUv;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn mib(b: u64) -> f64 {
    b as f64 / (1024.0 * 1024.0)
}

/// Signed error of `estimate` against `actual`, percent.
fn pct(estimate: u64, actual: u64) -> f64 {
    100.0 * (estimate as f64 / actual as f64 - 1.0)
}

/// Bakes like [`bake`] and measures the most memory the bake held at once beyond what was held
/// before it, MiB.
fn bake_measured(
    scene: &Scene,
    res: u32,
    n: u32,
    variants: u32,
    layout: PnmtLayout,
) -> (linespace::BakedLineSpace, f64, f64) {
    let before = held::start();
    let (ls, ms) = bake(scene, res, n, variants, layout);
    (ls, ms, mib(held::peak_since(before) as u64))
}

/// The GPU of `KILN_BENCH_GPU=1` (opened once, before the first row).
static GPU: std::sync::OnceLock<Option<linespace::gpu::GpuBaker>> = std::sync::OnceLock::new();

fn gpu() -> Option<&'static linespace::gpu::GpuBaker> {
    GPU.get_or_init(|| {
        std::env::var_os("KILN_BENCH_GPU").map(|_| {
            let t = Instant::now();
            let options = kiln_gpubake::Options { allow_cpu: true, validate: false };
            let gpu = linespace::gpu::GpuBaker::new(&options).expect("KILN_BENCH_GPU: a Vulkan device");
            let opened = t.elapsed().as_secs_f64() * 1e3;
            // The buffers of an N = 5 bake, as `kiln compile` makes them while it opens the GPU
            // during the stages before the line space.
            gpu.warm(5, COMPACT).expect("GPU buffers");
            println!(
                "GPU bake on {} (opened in {opened:.0} ms, its buffers made in {:.0} ms more; neither is in the times below)",
                gpu.device(),
                t.elapsed().as_secs_f64() * 1e3 - opened
            );
            gpu
        })
    })
    .as_ref()
}

fn bake(
    scene: &Scene,
    res: u32,
    n: u32,
    variants: u32,
    layout: PnmtLayout,
) -> (linespace::BakedLineSpace, f64) {
    bake_on(gpu(), scene, res, n, variants, layout)
}

fn bake_on(
    gpu: Option<&linespace::gpu::GpuBaker>,
    scene: &Scene,
    res: u32,
    n: u32,
    variants: u32,
    layout: PnmtLayout,
) -> (linespace::BakedLineSpace, f64) {
    let t = Instant::now();
    let geometry = kiln_compiler::analyze::geometry::SceneGeometry::new(scene);
    let voxels = geometry.voxels(res).clone();
    let voxel_ms = t.elapsed().as_secs_f64() * 1e3;
    // As `--line-space-device auto` decides (unless KILN_BENCH_GPU=all).
    let work = voxels.triangles.len() as u64 * kiln_format::linespace::index::shafts_per_voxel(n) as u64;
    let all = std::env::var("KILN_BENCH_GPU").is_ok_and(|v| v == "all");
    let gpu = gpu.filter(|_| all || work >= linespace::gpu::AUTO_MIN_WORK);
    let progress = kiln_compiler::progress::Progress::hidden();
    let ls = linespace::bake(gpu, &attributes(scene), voxels, voxel_ms, n, variants, layout, None, &progress)
        .expect("bake");
    (ls, t.elapsed().as_secs_f64() * 1e3)
}

/// Bytes per filled shaft of each variant, in memory and as the file's default codec stores it
/// (estimated from samples of the larger sections), and what the compact PNMT records of `ls`
/// cost in error against the full records of `full`, measured on every record.
fn memory(ls: &linespace::BakedLineSpace, full: &linespace::BakedLineSpace, lc: &linespace::BakedLineSpace) {
    let filled = ls.header.filled.max(1) as f64;
    let binary = 4 * (ls.bits.len() + ls.ranks.len() + ls.slots.len());
    let records: &[u8] = bytemuck::cast_slice(&ls.pnmt);
    // The codec's compressed size, estimated from at most 16 evenly spaced 4 MiB pieces: the
    // fine rows' sections are gigabytes, which the single-threaded level-9 encoder takes
    // minutes over.
    let zstd = |b: &[u8]| {
        const PIECE: usize = 4 << 20;
        let pieces = b.len().div_ceil(PIECE).max(1);
        let (mut raw, mut framed) = (0usize, 0usize);
        for i in (0..pieces).step_by(pieces.div_ceil(16)) {
            let piece = &b[i * PIECE..((i + 1) * PIECE).min(b.len())];
            raw += piece.len();
            framed +=
                kiln_format::codec::compress_zstd(piece, 1).map_or(piece.len(), |f| f.len().min(piece.len()));
        }
        (b.len() as f64 * framed as f64 / raw.max(1) as f64) as usize
    };
    let entries: &[u8] = bytemuck::cast_slice(&lc.candidates);
    let offsets: &[u8] = bytemuck::cast_slice(&lc.candidate_offsets);
    let (mut pos_max, mut pos_sum, mut ang_max, mut ang_sum, mut count) = (0f64, 0f64, 0f64, 0f64, 0u64);
    let mut differ = 0u64;
    let (lw, fw) = (ls.pnmt_layout().words(), PnmtLayout::Full.words());
    assert_eq!(ls.pnmt.len() / lw, full.pnmt.len() / fw, "the two bakes' record counts");
    for (c, f) in ls.pnmt.chunks_exact(lw).zip(full.pnmt.chunks_exact(fw)) {
        let (c, f) = (
            ls.pnmt_layout().decode(c, glam::DVec3::ZERO, 1.0),
            PnmtLayout::Full.decode(f, glam::DVec3::ZERO, 1.0),
        );
        let (Some(c), Some(f)) = (c, f) else {
            differ += (c.is_some() != f.is_some()) as u64;
            continue;
        };
        // Cell units (both decoded in the unit cell); the largest axis.
        let e = (c.position - f.position).abs().max_element();
        // atan2(|a × b|, a · b) in f64: acos of an f32 dot product near 1 errs by 0.02°.
        let (a, b) = (c.normal.as_dvec3(), f.normal.as_dvec3());
        let angle = a.cross(b).length().atan2(a.dot(b)).to_degrees();
        differ += (c.material != f.material) as u64;
        (pos_max, pos_sum, ang_max, ang_sum, count) =
            (pos_max.max(e), pos_sum + e, ang_max.max(angle), ang_sum + angle, count + 1);
    }
    let n = count.max(1) as f64;
    let full_bytes: &[u8] = bytemuck::cast_slice(&full.pnmt);
    println!(
        "      bytes per filled shaft: binary {:.2} ({:.2} zstd), PNMT {} {:.1} ({:.1} zstd), full {:.1} ({:.1} zstd), candidates {:.1} ({:.1} zstd); {} against full records: position error max {:.2e} mean {:.2e} cells, normal max {:.3} mean {:.3} degrees, {differ} records differing in presence or material",
        binary as f64 / filled,
        (zstd(bytemuck::cast_slice(&ls.bits))
            + zstd(bytemuck::cast_slice(&ls.ranks))
            + zstd(bytemuck::cast_slice(&ls.slots))) as f64
            / filled,
        ls.pnmt_layout().name(),
        records.len() as f64 / filled,
        zstd(records) as f64 / filled,
        full_bytes.len() as f64 / filled,
        zstd(full_bytes) as f64 / filled,
        (entries.len() + offsets.len()) as f64 / lc.header.filled.max(1) as f64,
        (zstd(entries) + zstd(offsets)) as f64 / lc.header.filled.max(1) as f64,
        ls.pnmt_layout().name(),
        pos_max,
        pos_sum / n,
        ang_max,
        ang_sum / n,
    );
}

fn main() {
    let rows: Vec<usize> = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with('-'))
        .map(|s| s.split(',').filter_map(|x| x.parse::<usize>().ok()).map(|x| x - 1).collect())
        .unwrap_or_else(|| (0..TABLE1.len()).collect());
    let runs: usize = std::env::var("KILN_BENCH_RUNS").ok().and_then(|s| s.parse().ok()).unwrap_or(3);
    gpu();
    println!(
        "line-space bake, {} threads, median of {runs} runs; thesis: GTX 1080, PNMT",
        rayon::current_num_threads()
    );
    println!(
        "{:>3} {:>6} {:>9} {:>3} | {:>9} {:>9} | {:>10} {:>10} {:>7} | {:>10} {:>10} {:>7} | {:>8} {:>9} {:>9}",
        "row",
        "scene",
        "triangles",
        "N",
        "grid",
        "voxel ms",
        "PNMT ms",
        "thesis ms",
        "ratio",
        "cand. ms",
        "thesis ms",
        "ratio",
        "slots",
        "PNMT MiB",
        "cand. MiB"
    );
    for &r in &rows {
        let row = &TABLE1[r];
        let scene = cornell_with_object(row.object, 42);
        let tris = scene.triangles.len();
        let mut voxel = Vec::new();
        let (mut pnmt_ms, mut cand_ms) = (Vec::new(), Vec::new());
        let mut last = None;
        let mut peaks = (0.0f64, 0.0f64);
        for _ in 0..runs {
            // The previous run's results are dropped first, so that the peaks measure one bake.
            drop(last.take());
            let (ls, ms, peak_pnmt) =
                bake_measured(&scene, row.res, row.n, Variants::BINARY | Variants::PNMT, COMPACT);
            if gpu().is_some() && pnmt_ms.is_empty() {
                println!("      PNMT baked on {}", ls.device.as_deref().unwrap_or("the CPU"));
            }
            voxel.push(ls.voxel_ms);
            pnmt_ms.push(ms - ls.voxel_ms);
            let (lc, ms, peak_cand) =
                bake_measured(&scene, row.res, row.n, Variants::BINARY | Variants::CANDIDATES, COMPACT);
            cand_ms.push(ms - lc.voxel_ms);
            peaks = (peaks.0.max(peak_pnmt), peaks.1.max(peak_cand));
            last = Some((ls, lc));
        }
        let (ls, lc) = last.expect("runs >= 1");
        let (p, c) = (median(pnmt_ms), median(cand_ms));
        println!(
            "{:>3} {:>6} {:>9} {:>3} | {:>9} {:>9.1} | {:>10.1} {:>10.0} {:>7.3} | {:>10.1} {:>10.0} {:>7.3} | {:>8} {:>9.1} {:>9.1}",
            r + 1,
            row.scene,
            tris,
            row.n,
            format!("{}x{}x{}", ls.header.dims[0], ls.header.dims[1], ls.header.dims[2]),
            median(voxel),
            p,
            row.thesis_ls_ms,
            p / row.thesis_ls_ms,
            c,
            row.thesis_ls_ms,
            c / row.thesis_ls_ms,
            ls.header.slots,
            mib(4 * (ls.pnmt.len() + ls.bits.len() + ls.ranks.len() + ls.slots.len()) as u64),
            mib(4
                * (lc.candidates.len()
                    + lc.candidate_offsets.len()
                    + lc.bits.len()
                    + lc.ranks.len()
                    + lc.slots.len()) as u64),
        );
        let (full, full_ms, peak_full) =
            bake_measured(&scene, row.res, row.n, Variants::BINARY | Variants::PNMT, PnmtLayout::Full);
        memory(&ls, &full, &lc);
        println!(
            "      bake's peak memory (bytes held beyond those before it): PNMT {:.1} MiB (full records {:.1} MiB), candidates {:.1} MiB; full records' bake {:.1} ms (1 run)",
            peaks.0,
            peak_full,
            peaks.1,
            full_ms - full.voxel_ms
        );
        drop(full);
        if gpu().is_some() {
            let (cpu, cpu_ms) =
                bake_on(None, &scene, row.res, row.n, Variants::BINARY | Variants::PNMT, COMPACT);
            let same = cpu.bits == ls.bits && cpu.ranks == ls.ranks && cpu.pnmt == ls.pnmt;
            let differing = cpu.pnmt.iter().zip(&ls.pnmt).filter(|(a, b)| a != b).count();
            println!(
                "      GPU against CPU bake ({:.1} ms on the CPU): {} (bit words {} / {}, record words differing {differing})",
                cpu_ms - cpu.voxel_ms,
                if same { "the same bits, ranks and records" } else { "DIFFERENT" },
                cpu.bits.len(),
                ls.bits.len()
            );
        }
        let _ = row.thesis_voxel_ms;
        let t = Instant::now();
        let geometry = kiln_compiler::analyze::geometry::SceneGeometry::new(&scene);
        let central = Estimate::with_errors(&geometry, row.res, row.n, 0.0).with_pnmt_layout(COMPACT);
        let bound = Estimate::new(&geometry, row.res, row.n).with_pnmt_layout(COMPACT);
        let estimate_ms = t.elapsed().as_secs_f64() * 1e3 / 2.0;
        let grid = 96 + 4 * (ls.voxel_offsets.len() + ls.voxel_triangles.len()) as u64;
        let binary = 4 * (ls.bits.len() + ls.ranks.len() + ls.slots.len()) as u64;
        let with_pnmt = grid + binary + 4 * ls.pnmt.len() as u64;
        let with_cand = grid + binary + 4 * (lc.candidates.len() + lc.candidate_offsets.len()) as u64;
        let pn = Variants::BINARY | Variants::PNMT;
        let bc = Variants::BINARY | Variants::CANDIDATES;
        println!(
            "      estimate ({estimate_ms:.0} ms): grid+binary+PNMT {:.1} MiB central {:+.1}%, bound {:+.1}%; grid+binary+candidates {:.1} MiB central {:+.1}%, bound {:+.1}%",
            mib(with_pnmt),
            pct(central.bytes.total(pn), with_pnmt),
            pct(bound.bytes.total(pn), with_pnmt),
            mib(with_cand),
            pct(central.bytes.total(bc), with_cand),
            pct(bound.bytes.total(bc), with_cand),
        );
        println!(
            "      tests {} ({:.2} per candidate entry; the PNMT bake {}), filled {} ({:.1}%), false fills {:.3}% (of 20,000 sampled), entries {}, PNMT records missing {}",
            lc.tests,
            lc.tests as f64 / lc.header.entries.max(1) as f64,
            ls.tests,
            ls.header.filled,
            100.0 * ls.header.filled as f64 / (ls.header.slots as f64 * 15.0 * (row.n as f64).powi(4)),
            100.0 * linespace::false_fill_rate(&attributes(&scene), &ls, 20_000),
            lc.header.entries,
            ls.pnmt_missing
        );
    }
}
