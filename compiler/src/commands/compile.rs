//! `kiln compile` and `kiln demo`.

use std::path::PathBuf;
use std::time::Instant;

use crate::cli::{CompileArgs, DemoArgs};
use crate::exit::CliResult;
use crate::output::size;
use crate::pipeline::{self, Report};

/// Runs `kiln compile`.
pub fn run(args: &CompileArgs) -> CliResult {
    let loaded = pipeline::load(&args.scene, args.out.quiet)?;
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

/// Runs `kiln demo`.
pub fn demo(args: &DemoArgs) -> CliResult {
    let start = Instant::now();
    let mut scene = crate::import::demo::cornell_box();
    let settings = pipeline::configure(&mut scene, args.config.as_deref(), &args.bake)?;
    let loaded = pipeline::finish(scene, settings, "demo", &Default::default(), args.out.quiet, start)?;
    let report = pipeline::compile(&loaded, "demo", &args.output, &args.out)?;
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
    for s in r.stages.iter().filter(|s| !s.run) {
        println!("  skipped {}: {}", s.stage, s.reason);
    }
}
