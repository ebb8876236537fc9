//! `--shadows none`: every light unshadowed.

use crate::render::techniques::{Knobs, Registered, Technique};

/// Every light unshadowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Off;

impl Registered for Off {
    const NAME: &'static str = "none";
    const HELP: &'static str = "no shadows";

    fn new(_: &Knobs) -> Result<Off, String> {
        Ok(Off)
    }
}

impl Technique for Off {}
