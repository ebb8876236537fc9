//! `--aa accumulate`: a running mean of the stochastic passes while the camera is still; any
//! change of view, projection or size restarts it.

use crate::render::techniques::{History, Knobs, Registered, Technique};

/// A running mean while the camera is still.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Accumulate;

impl Registered for Accumulate {
    const NAME: &'static str = "accumulate";
    const HELP: &'static str = "a running mean of the stochastic passes while the camera is still";

    fn new(_: &Knobs) -> Result<Accumulate, String> {
        Ok(Accumulate)
    }
}

impl Technique for Accumulate {
    fn history(&self) -> History {
        History::Still
    }
}
