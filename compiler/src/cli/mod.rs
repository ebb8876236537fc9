//! Command-line definition (clap). Raw values are checked here; commands turn them into settings.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

/// kiln compiles glTF and OBJ scenes into .kiln files: geometry, textures, BVH and the baked
/// lighting structures a player needs, checksummed, versioned and ready to memory-map.
#[derive(Debug, Parser)]
#[command(name = "kiln", version, about, long_about = None, propagate_version = true)]
#[command(
    after_help = "Exit codes: 0 success, 1 bad input or failed verification, 2 usage error, \
3 unsupported (e.g. another major format version), 4 I/O failure."
)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Show a .kiln file's version, sections (kind, size, codec, checksum status) and manifest.
    Inspect(InspectArgs),
    /// Validate a .kiln file completely: layout, every checksum, every cross-reference.
    /// Exits 0 when the file is sound; otherwise prints one line saying what is wrong and where.
    Verify(VerifyArgs),
}

/// `kiln inspect`.
#[derive(Debug, Args)]
pub struct InspectArgs {
    /// The .kiln file.
    pub file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `kiln verify`.
#[derive(Debug, Args)]
pub struct VerifyArgs {
    /// The .kiln file.
    pub file: PathBuf,
    /// Print a JSON report instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Parses the process arguments; exits with code 2 and a usage message on error.
pub fn parse() -> Cli {
    Cli::parse()
}
