//! `--shadows none`: every light unshadowed.

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// Every light unshadowed.
    Off,
    "none",
    "no shadows"
}

impl Technique for Off {}
