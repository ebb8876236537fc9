//! `kiln compile` and `kiln demo`.

use std::path::PathBuf;
use std::time::Instant;

use crate::bench_scenes::{BUNNY, DRAGON, TEAPOT, cornell_with_object};
use crate::cli::{CompileArgs, DemoArgs, DemoScene};
use crate::exit::CliResult;
use crate::output::size;
use crate::pipeline::{self, Report};

/// Runs `kiln compile`.
pub fn run(args: &CompileArgs) -> CliResult {
    // -q hides progress and the summary, never a warning (-W CLASS=ignore does that).
    let loaded = pipeline::load(&args.scene, false)?;
    let output = args.output.clone().unwrap_or_else(|| {
        PathBuf::from(format!(
            "{}.kiln",
            args.scene.input.file_stem().map_or("scene".into(), |s| s.to_string_lossy())
        ))
    });
    let report = pipeline::compile(&loaded, &args.scene.input.display().to_string(), &output, &args.out)?;
    if !args.out.quiet {
        summary(&report);
    }
    Ok(())
}

/// Seed of the benchmark scenes' objects (as `benches/linespace.rs` and `benches/queries.rs`
/// use, so that the files match the benchmarks' scenes).
const SEED: u64 = 42;

/// Runs `kiln demo`.
pub fn demo(args: &DemoArgs) -> CliResult {
    let start = Instant::now();
    let (mut scene, name) = match args.scene {
        DemoScene::Demo => (crate::import::demo::cornell_box(), "demo"),
        DemoScene::Cornell => (cornell_with_object(0, SEED), "cornell"),
        DemoScene::BoxTeapot => (cornell_with_object(TEAPOT, SEED), "box-teapot"),
        DemoScene::BoxBunny => (cornell_with_object(BUNNY, SEED), "box-bunny"),
        DemoScene::BoxDragon => (cornell_with_object(DRAGON, SEED), "box-dragon"),
    };
    args.limits.apply(None, args.config.as_deref(), &args.bake);
    let settings = pipeline::configure(&mut scene, args.config.as_deref(), &args.bake)?;
    let loaded = pipeline::finish(scene, settings, name, &Default::default(), false, start)?;
    let report = pipeline::compile(&loaded, name, &args.output, &args.out)?;
    if !args.out.quiet {
        summary(&report);
    }
    Ok(())
}

fn summary(r: &Report) {
    let c = &r.counts;
    println!(
        "wrote {} ({}): {} triangles, {} vertices, {} materials, {} textures, {} lights, {} BVH nodes in {:.0} ms",
        r.output,
        size(r.bytes),
        c.triangles,
        c.vertices,
        c.materials,
        c.textures,
        c.lights,
        c.bvh_nodes,
        r.total_ms
    );
    if let Some(p) = &r.line_space_plan {
        let e = &p.estimate;
        println!(
            "  line space: {} cells on the longest axis (cell {:.4} scene units), N = {} (patch {:.4}), {}: estimated {}, written {}{}",
            e.voxel_res,
            e.cell,
            e.shaft_res,
            e.patch(),
            crate::settings::variants_name(p.variants),
            size(p.bytes),
            size(r.line_space_bytes),
            p.budget.map_or(String::new(), |b| format!(" (budget {})", size(b)))
        );
    }
    if let Some(dir) = &r.cache {
        let names = |cached: bool| -> String {
            let v: Vec<&str> = r
                .stages
                .iter()
                .filter(|s| s.run && s.cached == cached && !matches!(s.stage, "import" | "write"))
                .map(|s| s.stage)
                .collect();
            if v.is_empty() { "none".into() } else { v.join(", ") }
        };
        println!("  stage cache {dir}: cached {}; baked {}", names(true), names(false));
    }
    for s in r.stages.iter().filter(|s| !s.run) {
        println!("  skipped {}: {}", s.stage, s.reason);
    }
}
