//! One module per subcommand; [`run`] dispatches.

mod cache;
mod compile;
mod export;
mod inspect;
mod plan;
mod verify;

use crate::cli::{Cli, Command};
use crate::exit::CliResult;

/// Runs the parsed command.
pub fn run(cli: Cli) -> CliResult {
    match cli.command {
        Command::Compile(args) => compile::run(&args),
        Command::Plan(args) => plan::run(&args),
        Command::Demo(args) => compile::demo(&args),
        Command::Export(args) => export::run(&args),
        Command::Inspect(args) => inspect::run(&args),
        Command::Verify(args) => verify::run(&args),
        Command::Cache(c) => cache::run(&c),
        Command::Completions { shell } => {
            let mut cmd = <Cli as clap::CommandFactory>::command();
            clap_complete::generate(shell, &mut cmd, "kiln", &mut std::io::stdout().lock());
            Ok(())
        }
        Command::Man => {
            let cmd = <Cli as clap::CommandFactory>::command();
            clap_mangen::Man::new(cmd).render(&mut std::io::stdout().lock()).map_err(|e| {
                crate::exit::CliError::new(
                    crate::exit::Exit::Io,
                    format!("could not write the man page: {e}"),
                )
            })
        }
    }
}
