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
    /// What each texture becomes (`--texture-format`).
    texture_formats: Vec<TexturePlan>,
    warnings: Vec<String>,
}

#[derive(Serialize)]
struct TexturePlan {
    name: String,
    width: u32,
    height: u32,
    format: &'static str,
    why: &'static str,
}

/// Runs `kiln plan`.
pub fn run(args: &PlanArgs) -> CliResult {
    // Warnings go to stderr, also with --json (its output is stdout's).
    let loaded = pipeline::load(&args.scene, false)?;
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
        texture_formats: texture_plans(&loaded),
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
        if d.stage == crate::analyze::plan::Stage::Textures && d.run {
            for t in &j.texture_formats {
                println!("        {:<6} {}x{} {} ({})", t.format, t.width, t.height, t.name, t.why);
            }
        }
    }
    Ok(())
}

/// What each texture of `loaded` becomes, as the texture stage decides it.
fn texture_plans(loaded: &pipeline::Loaded) -> Vec<TexturePlan> {
    let materials: Vec<kiln_format::sections::GpuMaterial> =
        loaded.scene.materials.iter().map(|m| m.gpu).collect();
    loaded
        .scene
        .textures
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let c = crate::bake::bc::choose(
                t,
                crate::bake::bc::Usage::of(&materials, i as u32),
                loaded.settings.texture_format,
            );
            TexturePlan {
                name: t.name.clone(),
                width: t.width,
                height: t.height,
                format: c.format.name(),
                why: c.why,
            }
        })
        .collect()
}
