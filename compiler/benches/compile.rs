//! Compile benchmarks on `pica_pica` (76,274 triangles): per-stage compile time, the BVH stage
//! against calling obvhs directly, and "scene ready" from a `.kiln` against glTF import + BVH
//! build. Prints medians over interleaved runs and the ratios.
//!
//! `cargo bench -p kiln-compiler --bench compile` (KILN_BENCH_RUNS sets the run count, 11 by default).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use kiln_compiler::bake::bvh;
use kiln_compiler::cli::{BakeArgs, OutputArgs, SceneArgs};
use kiln_compiler::pipeline;
use kiln_compiler::settings::BvhPreset;
use kiln_format::{Checksums, KilnFile, SceneView};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn spread(v: &[f64]) -> (f64, f64) {
    (v.iter().copied().fold(f64::INFINITY, f64::min), v.iter().copied().fold(0.0, f64::max))
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let input = root.join("../shared/scenes/pica_pica/scene.gltf");
    if !input.is_file() {
        println!("skipped: {} is absent", input.display());
        return;
    }
    let runs: usize = std::env::var("KILN_BENCH_RUNS").ok().and_then(|s| s.parse().ok()).unwrap_or(11);
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("pica.kiln");
    let scene_args = SceneArgs {
        input: input.clone(),
        config: Some(root.join("tests/scenes/pica_pica.toml")),
        bake: BakeArgs {
            bvh_preset: Some(BvhPreset::Medium),
            shaft_variants: Some(0),
            ..BakeArgs::default()
        },
        strict: false,
    };
    let out_args = OutputArgs { report: None, depfile: None, threads: None, quiet: true };
    println!("pica_pica, {runs} runs, {} threads; medians (min..max) in ms", rayon::current_num_threads());

    // 1. Per-stage compile time.
    let mut stages: Vec<(String, Vec<f64>)> = Vec::new();
    let mut totals = Vec::new();
    for _ in 0..runs {
        let loaded = pipeline::load(&scene_args, true).expect("pica_pica loads");
        let report = pipeline::compile(&loaded, "pica", &out, &out_args).expect("pica_pica compiles");
        totals.push(report.total_ms);
        for s in report.stages {
            match stages.iter_mut().find(|(n, _)| n == s.stage) {
                Some((_, v)) => v.push(s.ms),
                None => stages.push((s.stage.to_string(), vec![s.ms])),
            }
        }
    }
    println!("\ncompile stages");
    for (name, v) in &stages {
        let (lo, hi) = spread(v);
        println!("  {name:<10} {:>8.2}  ({lo:.2}..{hi:.2})", median(v.clone()));
    }
    let (lo, hi) = spread(&totals);
    println!("  {:<10} {:>8.2}  ({lo:.2}..{hi:.2})", "total", median(totals.clone()));

    // 2. BVH stage vs obvhs directly, same triangles, interleaved.
    let loaded = pipeline::load(&scene_args, true).expect("pica_pica loads");
    let s = &loaded.scene;
    let tris = bvh::triangles(s.triangles.iter().map(|t| t.map(|i| s.vertices[i as usize].position)));
    let (mut ours, mut direct) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let t = Instant::now();
        let built = bvh::build(&tris, BvhPreset::Medium).expect("bvh");
        ours.push(ms(t.elapsed()));
        std::hint::black_box(built);
        let t = Instant::now();
        let mut core = Duration::ZERO;
        let raw =
            obvhs::cwbvh::builder::build_cwbvh_from_tris(&tris, bvh::params(BvhPreset::Medium), &mut core);
        direct.push(ms(t.elapsed()));
        std::hint::black_box(raw);
    }
    let (mo, md) = (median(ours.clone()), median(direct.clone()));
    println!("\nBVH over {} triangles (preset medium)", tris.len());
    println!("  kiln bvh stage      {mo:>8.2}  ({:.2}..{:.2})", spread(&ours).0, spread(&ours).1);
    println!("  obvhs directly      {md:>8.2}  ({:.2}..{:.2})", spread(&direct).0, spread(&direct).1);
    println!("  ratio stage/direct  {:>8.3}  (target <= 1.1)", mo / md);

    // 3. Scene ready: open the .kiln vs import glTF + build the BVH, interleaved.
    let (mut open_all, mut open_geo, mut open_lazy, mut import) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for _ in 0..runs {
        let t = Instant::now();
        let file = KilnFile::open(&out, Checksums::Eager).expect("open");
        let view = SceneView::new(&file).expect("valid");
        std::hint::black_box(view.bvh.len());
        open_all.push(ms(t.elapsed()));

        let t = Instant::now();
        let file = KilnFile::open(&out, Checksums::OnAccess).expect("open");
        let view = SceneView::new(&file).expect("valid");
        std::hint::black_box(view.bvh.len());
        open_geo.push(ms(t.elapsed()));

        let t = Instant::now();
        let file = KilnFile::open(&out, Checksums::Deferred).expect("open");
        let view = SceneView::new(&file).expect("valid");
        std::hint::black_box(view.bvh.len());
        open_lazy.push(ms(t.elapsed()));

        let t = Instant::now();
        let loaded = pipeline::load(&scene_args, true).expect("loads");
        let s = &loaded.scene;
        let tris = bvh::triangles(s.triangles.iter().map(|t| t.map(|i| s.vertices[i as usize].position)));
        std::hint::black_box(bvh::build(&tris, BvhPreset::Medium).expect("bvh"));
        import.push(ms(t.elapsed()));
    }
    let row = |name: &str, v: &[f64]| {
        let (lo, hi) = spread(v);
        println!("  {name:<38} {:>8.2}  ({lo:.2}..{hi:.2})", median(v.to_vec()));
    };
    println!("\nscene ready: geometry, materials and BVH validated and usable in memory");
    row(".kiln, their checksums verified", &open_geo);
    row(".kiln, no checksums", &open_lazy);
    row(".kiln, every checksum (textures too)", &open_all);
    row("glTF import + BVH build", &import);
    let c = median(import.clone());
    println!("  speed-up, checksums verified           {:>8.1}x  (target >= 20)", c / median(open_geo));
    println!("  speed-up, no checksums                 {:>8.1}x", c / median(open_lazy));
    println!("  speed-up, every checksum               {:>8.1}x", c / median(open_all));
}
