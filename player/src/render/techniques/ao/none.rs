//! `--ao none`: no ambient occlusion (the material's occlusion texture still applies).

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// No ambient occlusion.
    Off,
    "none",
    "no ambient occlusion (the material's occlusion texture still applies)"
}

impl Technique for Off {}
