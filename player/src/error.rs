//! Exit codes of `kiln-play` and the error every operation returns.
//!
//! | code | meaning |
//! |---|---|
//! | 0 | success |
//! | 1 | bad input: an invalid or damaged `.kiln` file |
//! | 2 | usage error |
//! | 3 | unsupported: no Vulkan loader, no suitable device, a missing feature |
//! | 4 | I/O failure: a file that cannot be read or written |
//! | 5 | GPU failure while rendering (device lost, out of memory) |
//! | 6 | `kiln-bench --compare`: a point regressed |
//! | 70 | internal error (a bug) |

use std::fmt;

/// Exit status classes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exit {
    /// 1.
    BadInput = 1,
    /// 2.
    Usage = 2,
    /// 3.
    Unsupported = 3,
    /// 4.
    Io = 4,
    /// 5.
    Gpu = 5,
    /// 6.
    Regression = 6,
}

/// An error ending the program: one message and an exit code.
#[derive(Debug)]
pub struct PlayError {
    /// Exit code.
    pub exit: Exit,
    /// Message.
    pub message: String,
}

impl PlayError {
    /// An error of class `exit`.
    pub fn new(exit: Exit, message: impl Into<String>) -> Self {
        Self { exit, message: message.into() }
    }
}

impl fmt::Display for PlayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for PlayError {}

/// Result of the player's operations.
pub type PlayResult<T = ()> = Result<T, PlayError>;

/// Maps a Vulkan error of operation `what` to an exit class.
pub fn vk(what: &str, e: crate::gpu::vk::Result) -> PlayError {
    use crate::gpu::vk::Result as R;
    let exit = match e {
        R::ERROR_INCOMPATIBLE_DRIVER
        | R::ERROR_EXTENSION_NOT_PRESENT
        | R::ERROR_FEATURE_NOT_PRESENT
        | R::ERROR_LAYER_NOT_PRESENT => Exit::Unsupported,
        _ => Exit::Gpu,
    };
    PlayError::new(exit, format!("{what} failed: {e}"))
}
