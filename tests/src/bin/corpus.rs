//! `corpus`: compiles, verifies and renders every model of `tests/corpus/models.toml` and prints
//! the table (tests/corpus/run; docs/corpus.md holds a run of it).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;

/// Compile, verify and render (64x48) every model of tests/corpus/models.toml, as `kiln compile`,
/// `kiln verify` and `kiln-play --headless` would, and print a Markdown table: model, licence,
/// triangles, warnings by class, compile time, file size, verify, render. Absent models are
/// listed with where to get them. Exit 1 when a present model fails.
#[derive(Debug, Parser)]
#[command(name = "corpus")]
struct Args {
    /// Also write the table to this file.
    #[arg(long, value_name = "FILE")]
    markdown: Option<PathBuf>,
    /// Only the models whose name contains this (case-insensitive).
    #[arg(long)]
    only: Option<String>,
    /// Leave the render out (no Vulkan here).
    #[arg(long)]
    no_render: bool,
    /// Keep the compiled files, reports and images in this folder (default: a temporary one).
    #[arg(long, value_name = "DIR")]
    keep: Option<PathBuf>,
    /// More `kiln compile` flags for every model (after `--`), e.g. `-- --probes off`.
    #[arg(last = true)]
    compile_flags: Vec<String>,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let entries = match kiln_tests::corpus::entries() {
        Ok(e) => e,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    };
    let temp = tempfile::tempdir().expect("a temporary folder");
    let work = args.keep.clone().unwrap_or_else(|| temp.path().to_path_buf());
    if let Err(e) = std::fs::create_dir_all(&work) {
        eprintln!("error: {}: {e}", work.display());
        return ExitCode::from(4);
    }
    let only = args.only.as_ref().map(|o| o.to_lowercase());
    let mut rows = Vec::new();
    for e in entries.iter().filter(|e| only.as_ref().is_none_or(|o| e.name.to_lowercase().contains(o))) {
        eprintln!("corpus: {} ...", e.name);
        let row = kiln_tests::corpus::run(e, &work, !args.no_render, &args.compile_flags);
        eprintln!(
            "corpus: {} {}",
            e.name,
            if row.skipped.is_some() {
                "absent"
            } else if row.passed() {
                "ok"
            } else {
                "FAILED"
            }
        );
        rows.push(row);
    }
    let table = kiln_tests::corpus::table(&rows);
    println!("{table}");
    if let Some(path) = &args.markdown
        && let Err(e) = std::fs::write(path, &table)
    {
        eprintln!("error: {}: {e}", path.display());
        return ExitCode::from(4);
    }
    if rows.iter().all(|r| r.passed()) { ExitCode::SUCCESS } else { ExitCode::from(1) }
}
