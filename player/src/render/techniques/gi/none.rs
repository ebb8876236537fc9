//! `--gi none`: no indirect diffuse light; the constant sky, darkened by AO where it runs.

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// No indirect diffuse light.
    Off,
    "none",
    "no indirect diffuse light: the sky lights every surface unoccluded (times AO where it runs)"
}

impl Technique for Off {}
