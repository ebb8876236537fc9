//! `kiln-bench`: every technique as a point of (GPU time, error against the reference) (see
//! `kiln-bench --help`).

use std::process::ExitCode;

use clap::Parser;
use kiln_player::sweep::cli::{Args, run};

fn main() -> ExitCode {
    kiln_player::gpu::process::quiet_on_closed_stdout();
    match run(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit as u8)
        }
    }
}
