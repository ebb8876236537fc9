//! `--aa none`: every frame shows its own samples.

use crate::render::techniques::{Knobs, Registered, Technique};

/// Every frame its own samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Off;

impl Registered for Off {
    const NAME: &'static str = "none";
    const HELP: &'static str = "every frame shows its own samples";

    fn new(_: &Knobs) -> Result<Off, String> {
        Ok(Off)
    }
}

impl Technique for Off {}
