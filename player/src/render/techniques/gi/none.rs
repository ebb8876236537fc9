//! `--gi none`: no indirect diffuse light; the constant sky, darkened by AO where it runs.

use crate::render::techniques::{Knobs, Registered, Technique};

/// No indirect diffuse light.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Off;

impl Registered for Off {
    const NAME: &'static str = "none";
    const HELP: &'static str =
        "no indirect diffuse light: the sky lights every surface unoccluded (times AO where it runs)";

    fn new(_: &Knobs) -> Result<Off, String> {
        Ok(Off)
    }
}

impl Technique for Off {}
