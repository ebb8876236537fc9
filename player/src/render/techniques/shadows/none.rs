//! `--shadows none`: every light unshadowed, the emissive surfaces' direct light too.

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// Every light unshadowed.
    Off,
    "none",
    "no shadows (the emissive surfaces' direct light is unshadowed too)"
}

impl Technique for Off {
    fn rays(&self, _: &crate::render::techniques::RayScene, inputs: &mut crate::render::techniques::RayInputs) {
        inputs.rt.direct_visibility = 0;
    }
}
