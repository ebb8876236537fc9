//! `kiln-play`: the Vulkan player (see `kiln-play --help`).

use std::process::ExitCode;
use std::time::Instant;

use clap::Parser;
use kiln_player::cli::{Args, run};

fn main() -> ExitCode {
    let start = Instant::now();
    let args = Args::parse();
    match run(args, start) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit as u8)
        }
    }
}
