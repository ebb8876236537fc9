//! `kiln verify`: full validation of a file.

use kiln_format::{Checksums, KilnFile, SceneView};
use serde::Serialize;

use crate::cli::VerifyArgs;
use crate::exit::{CliError, CliResult, format_error};
use crate::output::print_json;

#[derive(Serialize)]
struct VerifyJson {
    path: String,
    ok: bool,
    /// The first problem found, when not ok.
    error: Option<String>,
    sections: usize,
    /// Sections of kinds this reader does not know: skipped, but their checksums verified.
    skipped_sections: Vec<String>,
}

/// Runs `kiln verify`.
pub fn run(args: &VerifyArgs) -> CliResult {
    let outcome = check(args);
    let path = args.file.display().to_string();
    let report = match &outcome {
        Ok((sections, skipped)) => VerifyJson {
            path,
            ok: true,
            error: None,
            sections: *sections,
            skipped_sections: skipped.clone(),
        },
        Err(e) => VerifyJson {
            path,
            ok: false,
            error: Some(e.message.clone()),
            sections: 0,
            skipped_sections: vec![],
        },
    };
    if args.json {
        print_json(&report);
    } else if outcome.is_ok() {
        for s in &report.skipped_sections {
            eprintln!(
                "warning: {}: section {s} is unknown to this kiln; skipped",
                report.path
            );
        }
        println!("{}: ok ({} sections)", report.path, report.sections);
    }
    outcome.map(|_| ())
}

fn check(args: &VerifyArgs) -> Result<(usize, Vec<String>), CliError> {
    let file =
        KilnFile::open(&args.file, Checksums::Eager).map_err(|e| format_error(&args.file, e))?;
    SceneView::new(&file).map_err(|e| format_error(&args.file, e))?;
    let skipped = file
        .skipped()
        .map(|s| {
            format!(
                "{}#{} (version {})",
                s.entry.kind, s.entry.index, s.entry.version
            )
        })
        .collect();
    Ok((file.sections().len(), skipped))
}
