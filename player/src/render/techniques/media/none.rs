//! `--media none`: no participating media.

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// No participating media.
    Off,
    "none",
    "no participating media"
}

impl Technique for Off {}
