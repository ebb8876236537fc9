//! `kiln verify`: full validation of a file, optionally with a ray check of its BVH.

use kiln_format::{Checksums, KilnFile, SceneView};
use serde::Serialize;

use crate::cli::VerifyArgs;
use crate::exit::{CliError, CliResult, format_error};
use crate::output::print_json;
use crate::raycheck::{BvhCheck, check_bvh};

#[derive(Serialize)]
struct VerifyJson {
    path: String,
    ok: bool,
    /// The first problem found, when not ok.
    error: Option<String>,
    sections: usize,
    /// Sections of kinds this reader does not know: skipped, but their checksums verified.
    skipped_sections: Vec<String>,
    /// The ray check, when `--rays` was given and the file has a BVH.
    bvh: Option<BvhCheck>,
}

/// Runs `kiln verify`.
pub fn run(args: &VerifyArgs) -> CliResult {
    let path = args.file.display().to_string();
    let mut report =
        VerifyJson { path, ok: false, error: None, sections: 0, skipped_sections: vec![], bvh: None };
    let outcome = check(args, &mut report);
    if let Err(e) = &outcome {
        report.error = Some(e.message.clone());
    }
    report.ok = outcome.is_ok();
    if args.json {
        print_json(&report);
    } else if outcome.is_ok() {
        for s in &report.skipped_sections {
            eprintln!("warning: {}: section {s} is unknown to this kiln; skipped", report.path);
        }
        if let Some(b) = &report.bvh {
            println!(
                "{}: bvh: {} rays (seed {}), {} hits, {} ties on shared edges, {} mismatches",
                report.path, b.rays, b.seed, b.hits, b.ties, b.mismatches
            );
        }
        println!("{}: ok ({} sections)", report.path, report.sections);
    }
    outcome
}

fn check(args: &VerifyArgs, report: &mut VerifyJson) -> CliResult {
    let file = KilnFile::open(&args.file, Checksums::Eager).map_err(|e| format_error(&args.file, e))?;
    let view = SceneView::new(&file).map_err(|e| format_error(&args.file, e))?;
    report.sections = file.sections().len();
    report.skipped_sections = file
        .skipped()
        .map(|s| format!("{}#{} (version {})", s.entry.kind, s.entry.index, s.entry.version))
        .collect();
    if let Some(n) = args.rays {
        if view.bvh.is_empty() || view.triangles.is_empty() {
            return Err(CliError::input(format!(
                "{}: --rays needs a BVH and triangles; the file has none",
                report.path
            )));
        }
        let b = check_bvh(&view, n, args.seed);
        let bad = b.mismatches;
        let first = b.examples.first().cloned().unwrap_or_default();
        report.bvh = Some(b);
        if bad > 0 {
            return Err(CliError::input(format!(
                "{}: section CWBV: {bad} of {n} rays disagree with brute force; first: {first}",
                report.path
            )));
        }
    }
    Ok(())
}
