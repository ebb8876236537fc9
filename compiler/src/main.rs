//! `kiln`: parse the command line, run one command, map its outcome to an exit code.

use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = kiln_compiler::cli::parse();
    match kiln_compiler::commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let mut err = std::io::stderr().lock();
            let _ = writeln!(err, "error: {e}");
            ExitCode::from(e.exit as u8)
        }
    }
}
