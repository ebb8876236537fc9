//! `--aa accumulate`: a running mean of the stochastic passes while the camera is still; any
//! change of view, projection or size restarts it.

use crate::render::techniques::{History, Technique, plain_technique};

plain_technique! {
    /// A running mean while the camera is still.
    Accumulate,
    "accumulate",
    "a running mean of the stochastic passes while the camera is still"
}

impl Technique for Accumulate {
    fn history(&self) -> History {
        History::Still
    }
}
