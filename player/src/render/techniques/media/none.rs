//! `--media none`: no participating media.

use crate::render::techniques::{Knobs, Registered, Technique};

/// No participating media.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Off;

impl Registered for Off {
    const NAME: &'static str = "none";
    const HELP: &'static str = "no participating media";

    fn new(_: &Knobs) -> Result<Off, String> {
        Ok(Off)
    }
}

impl Technique for Off {}
