//! `kiln plan`: what a compile would do, and why, without writing anything.

use serde::Serialize;

use crate::analyze::plan::Decision;
use crate::cli::PlanArgs;
use crate::exit::CliResult;
use crate::output::print_json;
use crate::pipeline;

#[derive(Serialize)]
struct PlanJson<'a> {
    input: String,
    settings: Vec<(String, String)>,
    triangles: usize,
    materials: usize,
    textures: usize,
    lights: usize,
    cameras: usize,
    media: usize,
    stages: &'a [Decision],
    /// The line space's configuration, estimated size and why.
    line_space: Option<&'a crate::analyze::budget::Choice>,
    warnings: Vec<String>,
}

/// Runs `kiln plan`.
pub fn run(args: &PlanArgs) -> CliResult {
    let loaded = pipeline::load(&args.scene, args.json)?;
    let s = &loaded.scene;
    let j = PlanJson {
        input: args.scene.input.display().to_string(),
        settings: loaded.settings.pairs(),
        triangles: s.triangles.len(),
        materials: s.materials.len(),
        textures: s.textures.len(),
        lights: s.lights.len(),
        cameras: s.cameras.len(),
        media: s.media.len(),
        stages: &loaded.plan.stages,
        line_space: loaded.plan.line_space.as_ref(),
        warnings: s.warnings.iter().map(|w| w.message.clone()).collect(),
    };
    if args.json {
        print_json(&j);
        return Ok(());
    }
    println!(
        "{}: {} triangles, {} materials, {} textures, {} lights, {} cameras, {} media",
        j.input, j.triangles, j.materials, j.textures, j.lights, j.cameras, j.media
    );
    for d in j.stages {
        println!("  {:<5} {:<12} {}", if d.run { "run" } else { "skip" }, d.stage.name(), d.reason);
    }
    Ok(())
}
