//! `--denoise none`: the composition reads the ray-traced passes' running means as they are.

use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// No denoiser.
    Off,
    "none",
    "the ray-traced signals as traced: one sample per pixel and frame, averaged over the frames the \
     camera is still (or reprojected with --aa reproject|taa)"
}

impl Technique for Off {}
