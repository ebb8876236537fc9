//! `--reflections none`: the split-sum ambient specular only.

use crate::render::techniques::{Knobs, Registered, Technique};

/// The split-sum ambient only.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Off;

impl Registered for Off {
    const NAME: &'static str = "none";
    const HELP: &'static str = "split-sum ambient specular only";

    fn new(_: &Knobs) -> Result<Off, String> {
        Ok(Off)
    }
}

impl Technique for Off {}
