//! Compile benchmarks. `tiny`: a 12-triangle glTF box (the Khronos "Box" sample rebuilt in code)
//! compiled from import to bytes, as a fresh `kiln compile` process and in-process, and the BRDF
//! table stage alone at its default resolution. `pica`: `pica_pica` (76,274 triangles): per-stage
//! compile time, the BVH stage against calling obvhs directly, and "scene ready" from a `.kiln`
//! against glTF import + BVH build. Prints medians over interleaved runs and the ratios.
//!
//! `cargo bench -p kiln-compiler --bench compile [-- tiny|pica]` (KILN_BENCH_RUNS sets the run
//! count, 11 by default; a name runs only the cases containing it).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use kiln_compiler::bake::{brdf_lut, bvh};
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
    let runs: usize = std::env::var("KILN_BENCH_RUNS").ok().and_then(|s| s.parse().ok()).unwrap_or(11);
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let wanted = |case: &str| filter.as_deref().is_none_or(|f| case.contains(f));
    if wanted("tiny") {
        tiny(runs);
    }
    if wanted("pica") {
        pica(runs);
    }
}

/// Writes the Khronos "Box" sample's geometry (24 vertices, 12 triangles, one red PBR material
/// with the default roughness 1) as `box.gltf` + `box.bin` into `dir`.
fn write_box(dir: &std::path::Path) -> PathBuf {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut indices: Vec<u16> = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = positions.len() as u16;
            for (a, b) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
                let mut p = [0.0f32; 3];
                p[axis] = 0.5 * sign;
                p[u] = a;
                p[v] = b * sign;
                positions.push(p);
                let mut n = [0.0f32; 3];
                n[axis] = sign;
                normals.push(n);
            }
            indices.extend([0, 1, 2, 0, 2, 3].map(|k| base + k));
        }
    }
    let mut bin: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    let p_off = bin.len();
    bin.extend(positions.iter().flatten().flat_map(|f| f.to_le_bytes()));
    let n_off = bin.len();
    bin.extend(normals.iter().flatten().flat_map(|f| f.to_le_bytes()));
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1, "NORMAL": 2}, "indices": 0, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.0, 0.0, 1.0], "metallicFactor": 0.0}}],
        "accessors": [
            {"bufferView": 0, "componentType": 5123, "count": 36, "type": "SCALAR"},
            {"bufferView": 1, "componentType": 5126, "count": 24, "type": "VEC3",
             "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
            {"bufferView": 2, "componentType": 5126, "count": 24, "type": "VEC3"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": p_off},
            {"buffer": 0, "byteOffset": p_off, "byteLength": n_off - p_off},
            {"buffer": 0, "byteOffset": n_off, "byteLength": bin.len() - n_off},
        ],
        "buffers": [{"uri": "box.bin", "byteLength": bin.len()}],
    });
    std::fs::write(dir.join("box.bin"), &bin).expect("write box.bin");
    let path = dir.join("box.gltf");
    std::fs::write(&path, serde_json::to_vec_pretty(&json).expect("json")).expect("write box.gltf");
    path
}

/// The 12-triangle box: `kiln compile` as a fresh process (what a build system pays per call),
/// the same compile in-process, and the BRDF table stage alone, interleaved.
fn tiny(runs: usize) {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = write_box(dir.path());
    let out = dir.path().join("box.kiln");
    let scene_args = SceneArgs {
        input: input.clone(),
        config: None,
        bake: BakeArgs::default(),
        strict: false,
        warning_levels: Vec::new(),
        max_file_size: None,
        max_image_side: None,
        limits: Default::default(),
    };
    let out_args = quiet_output();
    let res = kiln_compiler::settings::BRDF_LUT_RES.default;
    let (mut process, mut in_process, mut lut) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..runs {
        let t = Instant::now();
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_kiln"))
            .args(["compile", "--quiet", "-o"])
            .arg(&out)
            .arg(&input)
            .status()
            .expect("kiln runs");
        assert!(status.success(), "kiln compile box.gltf failed");
        process.push(ms(t.elapsed()));

        let t = Instant::now();
        let loaded = pipeline::load(&scene_args, true).expect("box loads");
        let report = pipeline::compile(&loaded, "box", &out, &out_args).expect("box compiles");
        in_process.push(ms(t.elapsed()));
        assert_eq!(report.counts.triangles, 12);

        let t = Instant::now();
        std::hint::black_box(brdf_lut::bake(res));
        lut.push(ms(t.elapsed()));
    }
    println!(
        "tiny: 12-triangle glTF box, {runs} runs, {} threads; medians (min..max) in ms",
        rayon::current_num_threads()
    );
    let row = |name: &str, v: &[f64]| {
        let (lo, hi) = spread(v);
        println!("  {name:<44} {:>8.2}  ({lo:.2}..{hi:.2})", median(v.to_vec()));
    };
    row("kiln compile, fresh process (target <= 100)", &process);
    row("import + compile + write, in-process", &in_process);
    row(&format!("brdf-lut stage alone at {res}x{res}, uncached"), &lut);
    println!();
}

/// `pica_pica`: per-stage times, BVH against obvhs, and scene-ready times.
fn pica(runs: usize) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let input = root.join("../shared/scenes/pica_pica/scene.gltf");
    if !input.is_file() {
        println!("skipped: {} is absent", input.display());
        return;
    }
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
        warning_levels: Vec::new(),
        max_file_size: None,
        max_image_side: None,
        limits: Default::default(),
    };
    let out_args = quiet_output();
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

/// Output options of a quiet compile without report, depfile or stage cache.
fn quiet_output() -> OutputArgs {
    OutputArgs {
        report: None,
        depfile: None,
        threads: None,
        line_space_device: Default::default(),
        quiet: true,
        cache: None,
        no_cache: true,
    }
}
