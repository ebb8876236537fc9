//! One module per subcommand; [`run`] dispatches.

mod inspect;
mod verify;

use crate::cli::{Cli, Command};
use crate::exit::CliResult;

/// Runs the parsed command.
pub fn run(cli: Cli) -> CliResult {
    match cli.command {
        Command::Inspect(args) => inspect::run(&args),
        Command::Verify(args) => verify::run(&args),
    }
}
