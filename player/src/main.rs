//! `kiln-play`: the Vulkan player (see `kiln-play --help`).

use std::process::ExitCode;
use std::time::Instant;

use kiln_player::cli::{Invocation, parse_from, run, write_generated};

fn main() -> ExitCode {
    kiln_player::gpu::process::quiet_on_closed_stdout();
    let start = Instant::now();
    let invocation = match parse_from(std::env::args_os()) {
        Ok(i) => i,
        Err(e) => e.exit(),
    };
    let Invocation::Play(args) = invocation else {
        return match write_generated(&invocation, &mut std::io::stdout().lock()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: could not write to stdout: {e}");
                ExitCode::from(4)
            }
        };
    };
    match run(*args, start) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit as u8)
        }
    }
}
