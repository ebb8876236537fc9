//! `kiln-play`: the Vulkan player. This release carries the command-line skeleton only.

use clap::Parser;

/// kiln-play renders .kiln files with Vulkan, headless or in a window.
#[derive(Debug, Parser)]
#[command(name = "kiln-play", version, about)]
struct Args {
    /// The .kiln file to play.
    file: Option<std::path::PathBuf>,
}

fn main() -> std::process::ExitCode {
    let args = Args::parse();
    match args.file {
        None => {
            println!(
                "kiln-play {} (format {}.{})",
                env!("CARGO_PKG_VERSION"),
                kiln_format::header::VERSION_MAJOR,
                kiln_format::header::VERSION_MINOR
            );
            std::process::ExitCode::SUCCESS
        }
        Some(path) => {
            eprintln!("error: {}: rendering is not available in this build of kiln-play yet", path.display());
            std::process::ExitCode::from(3)
        }
    }
}
