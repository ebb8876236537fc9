//! Exit codes and the error type every command returns.
//!
//! | code | meaning |
//! |---|---|
//! | 0 | success |
//! | 1 | bad input: an invalid or damaged file, a broken asset, a failed verification |
//! | 2 | usage error: unknown flag, missing argument, conflicting options |
//! | 3 | unsupported: another major format version, a feature this build lacks |
//! | 4 | I/O failure: a file that cannot be read or written |
//! | 70 | internal error (a bug in kiln) |

use std::fmt;

/// Exit code of an internal error (a panic caught at the top).
pub const INTERNAL_ERROR: u8 = 70;

/// Process exit status of `kiln`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exit {
    /// Bad input (1).
    BadInput = 1,
    /// Usage error (2).
    Usage = 2,
    /// Unsupported input (3).
    Unsupported = 3,
    /// I/O failure (4).
    Io = 4,
}

/// An error that ends a command: one message and an exit code.
#[derive(Debug)]
pub struct CliError {
    /// Exit code.
    pub exit: Exit,
    /// The message, printed after `error: `.
    pub message: String,
}

impl CliError {
    /// Error with exit code.
    pub fn new(exit: Exit, message: impl Into<String>) -> Self {
        Self { exit, message: message.into() }
    }
    /// Bad input.
    pub fn input(message: impl Into<String>) -> Self {
        Self::new(Exit::BadInput, message)
    }
    /// Usage error.
    pub fn usage(message: impl Into<String>) -> Self {
        Self::new(Exit::Usage, message)
    }
    /// I/O failure.
    pub fn io(message: impl Into<String>) -> Self {
        Self::new(Exit::Io, message)
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for CliError {}

/// Maps a format error on `path` to an exit code and message.
pub fn format_error(path: &std::path::Path, e: kiln_format::FormatError) -> CliError {
    use kiln_format::ErrorKind;
    let exit = match e.kind {
        ErrorKind::Io(_) | ErrorKind::NotAFile => Exit::Io,
        _ if e.is_unsupported() => Exit::Unsupported,
        _ => Exit::BadInput,
    };
    CliError::new(exit, format!("{}: {e}", path.display()))
}

/// Result of a command.
pub type CliResult<T = ()> = Result<T, CliError>;
