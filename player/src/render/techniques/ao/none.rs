//! `--ao none`: no ambient occlusion (the material's occlusion texture still applies).

use crate::render::techniques::{Knobs, Registered, Technique};

/// No ambient occlusion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Off;

impl Registered for Off {
    const NAME: &'static str = "none";
    const HELP: &'static str = "no ambient occlusion (the material's occlusion texture still applies)";

    fn new(_: &Knobs) -> Result<Off, String> {
        Ok(Off)
    }
}

impl Technique for Off {}
