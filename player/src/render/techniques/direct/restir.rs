//! `--direct restir`: ReSTIR DI (Bitterli et al. 2020): [`super::ris::Ris`]'s candidates, whose
//! reservoirs are reused from the previous frame (reprojected, where the surface matches) and
//! from neighbours, so that many emitters converge at one sample per pixel
//! (`passes/rt_direct.rs`, `shaders/rt/direct.glsl`: the combination rule and its bias).

use super::CANDIDATES;
use crate::render::techniques::knobs::{Knob, number, whole};
use crate::render::techniques::{Knobs, Registered, Technique};

/// Neighbours' reservoirs joined per pixel.
pub const SPATIAL: Knob = whole(number(
    "direct-spatial",
    "neighbours' reservoirs each pixel joins (spatial reuse; 0: none)",
    0.0,
    8.0,
    4.0,
    &[0.0, 4.0],
));

/// The previous frame's weight, in candidates.
pub const TEMPORAL: Knob = whole(number(
    "direct-temporal",
    "the previous frame's reservoir counts at most this many times the candidates (temporal reuse; \
     0: none)",
    0.0,
    64.0,
    20.0,
    &[0.0, 20.0],
));

/// Resampled importance sampling with reservoir reuse.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Restir {
    /// Candidates per pixel and frame.
    pub candidates: u32,
    /// Neighbours joined.
    pub spatial: u32,
    /// Cap of the previous frame's candidates, in multiples of `candidates`.
    pub temporal: u32,
}

impl Registered for Restir {
    const NAME: &'static str = "restir";
    const HELP: &'static str = "emissive surfaces' light by ReSTIR DI: resampled candidates per pixel, reservoirs \
                                reused from the previous frame and from neighbours, one shadow ray to the sample \
                                that shades (one more for the reused candidates; through the line space with \
                                --shadows linespace, else the BVH; none with --shadows none); averaged while the camera is still, reuse stopping once the average \
                                holds 8 frames (see --direct-candidates, --direct-spatial, --direct-temporal)";
    const KNOBS: &'static [Knob] = &[CANDIDATES, SPATIAL, TEMPORAL];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Restir, String> {
        Ok(Restir {
            candidates: k.whole("direct-candidates")?,
            spatial: k.whole("direct-spatial")?,
            temporal: k.whole("direct-temporal")?,
        })
    }
}

impl Technique for Restir {
    super::traced_direct!();
}
