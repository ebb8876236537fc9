//! `kiln`: parse the command line, run one command, map its outcome to an exit code.

use std::io::Write;
use std::process::ExitCode;
use std::sync::Mutex;

/// The message of a panic, kept for one clear error line instead of a backtrace.
static PANIC: Mutex<Option<String>> = Mutex::new(None);

fn main() -> ExitCode {
    let cli = kiln_compiler::cli::parse();
    // A panic is a bug in kiln or a dependency, never the user's fault; report it as one line
    // with a distinct exit code rather than a backtrace.
    std::panic::set_hook(Box::new(|info| {
        let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        if let Ok(mut p) = PANIC.lock() {
            p.get_or_insert(format!("{msg}{at}"));
        }
    }));
    let outcome = std::panic::catch_unwind(|| kiln_compiler::commands::run(cli));
    let mut err = std::io::stderr().lock();
    match outcome {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(e)) => {
            let _ = writeln!(err, "error: {e}");
            ExitCode::from(e.exit as u8)
        }
        Err(_) => {
            let what = PANIC.lock().ok().and_then(|p| p.clone()).unwrap_or_default();
            // `kiln inspect | head`: the reader closed the pipe after the lines it wanted. Rust
            // ignores SIGPIPE, so `println!` panics instead of the process ending as a C tool's
            // would; nothing went wrong that the user needs to hear about.
            if what.starts_with("failed printing to stdout") && what.contains("Broken pipe") {
                return ExitCode::SUCCESS;
            }
            let _ = writeln!(
                err,
                "error: internal error ({what}); this is a bug in kiln, please report it with the input"
            );
            ExitCode::from(kiln_compiler::exit::INTERNAL_ERROR)
        }
    }
}
