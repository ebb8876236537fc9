//! `--reflections none`: the split-sum ambient specular only.

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// The split-sum ambient only.
    Off,
    "none",
    "split-sum ambient specular only"
}

impl Technique for Off {}
