//! `--aa none`: every frame shows its own samples.

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// Every frame its own samples.
    Off,
    "none",
    "every frame shows its own samples"
}

impl Technique for Off {}
