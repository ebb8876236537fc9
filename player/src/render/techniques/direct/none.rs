//! `--direct none`: the emissive surfaces light nothing directly (they show where the camera
//! sees them; `--gi rt` still finds them with its bounce rays).

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// No direct light of emissive surfaces.
    Off,
    "none",
    "emissive surfaces light nothing directly (the camera still sees them; --gi rt finds them with its \
     bounce rays)"
}

impl Technique for Off {}
