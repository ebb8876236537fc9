//! `--direct none`: the emissive surfaces light nothing directly (they show where the camera
//! sees them; `--gi rt` still finds them with its bounce rays).

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// No direct light of emissive surfaces.
    Off,
    "none",
    "emissive surfaces light nothing directly (the camera still sees them; --gi rt finds them with its \
     bounce rays; --gi probes adds the light the compiler baked from them). The default frame of a file \
     with probes takes this where no probe gets 1 % of its light straight from emissive surfaces \
     (dim decals and indicator lights: Khronos ToyCar's 88,837 emissive triangles), and says so"
}

impl Technique for Off {}
