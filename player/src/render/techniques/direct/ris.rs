//! `--direct ris`: per pixel and frame, candidates on the emissive triangles (chosen in
//! proportion to power), one kept by resampled importance sampling towards the unshadowed light
//! it sends, one shadow ray (`passes/rt_direct.rs`, `shaders/rt/direct.glsl` with no reuse).

use super::CANDIDATES;
use crate::render::techniques::{Knob, Knobs, Registered, Technique};

/// Resampled importance sampling of the emissive triangles, without reuse.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ris {
    /// Candidates per pixel and frame.
    pub candidates: u32,
    /// Always 0: no neighbours.
    pub spatial: u32,
    /// Always 0: no previous frame.
    pub temporal: u32,
}

impl Registered for Ris {
    const NAME: &'static str = "ris";
    const HELP: &'static str = "emissive surfaces' light by resampled importance sampling: per pixel and frame, \
                                candidate points on emissive triangles, one kept towards the light it sends, one \
                                shadow ray (through the line space with --shadows linespace, else the BVH; none with \
                                --shadows none); averaged while the camera \
                                is still (see --direct-candidates)";
    const KNOBS: &'static [Knob] = &[CANDIDATES];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Ris, String> {
        Ok(Ris { candidates: k.whole("direct-candidates")?, spatial: 0, temporal: 0 })
    }
}

impl Technique for Ris {
    super::traced_direct!();
}
