//! `kiln cache stats` and `kiln cache gc`.

use std::path::{Path, PathBuf};

use crate::cache::{self, Cache};
use crate::cli::CacheCommand;
use crate::exit::{CliError, CliResult};
use crate::output::{print_json, size};

/// The directory given, else `KILN_CACHE`; a usage error when neither.
fn dir(given: Option<&Path>) -> CliResult<PathBuf> {
    Cache::dir_from(given).ok_or_else(|| {
        CliError::usage(format!("no cache directory: give one (kiln cache stats DIR) or set {}", cache::ENV))
    })
}

/// Runs `kiln cache ...`.
pub fn run(cmd: &CacheCommand) -> CliResult {
    match cmd {
        CacheCommand::Stats { dir: d, json } => {
            let s = cache::stats(&dir(d.as_deref())?)?;
            if *json {
                print_json(&s);
            } else {
                println!("{}: {} entries, {}", s.dir, s.entries, size(s.bytes));
                for st in &s.stages {
                    println!("  {:<18} {:>6} entries  {:>10}", st.stage, st.entries, size(st.bytes));
                }
            }
        }
        CacheCommand::Gc { dir: d, max_size, json } => {
            let d = dir(d.as_deref())?;
            let c = cache::gc(&d, *max_size)?;
            if *json {
                print_json(&c);
            } else {
                println!(
                    "{}: removed {} entries ({}), kept {} ({}, limit {})",
                    d.display(),
                    c.removed,
                    size(c.removed_bytes),
                    c.kept,
                    size(c.kept_bytes),
                    size(*max_size)
                );
            }
        }
    }
    Ok(())
}
