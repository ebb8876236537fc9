//! What the player's integration tests share: `kiln` run in process.

/// Runs `kiln ARGS` in this process (the compiler is a dev-dependency); panics if it fails.
pub fn kiln(args: &[&str]) {
    use clap::Parser;
    let cli = kiln_compiler::cli::Cli::parse_from(std::iter::once("kiln").chain(args.iter().copied()));
    kiln_compiler::commands::run(cli).unwrap();
}
