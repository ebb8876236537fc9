//! Ambient occlusion: the image the direct-light pass multiplies the sky's ambient by.

use super::knobs::{Knob, UNBOUNDED, number};
use super::techniques;
pub use crate::render::passes::ao::Radius;

techniques! {
    /// Ambient occlusion.
    Ao for Ao, default none::Off;
    none => Off,
    rt => Rt,
    sao => Sao,
    gtao => Gtao,
}

/// The AO radius in scene units, for every AO technique.
pub const AO_RADIUS: Knob = number(
    "ao-radius",
    "AO radius in scene units (rt: the ray length; sao, gtao: the world radius of the samples); \
     0: --ao-reach times the scene's diagonal",
    0.0,
    UNBOUNDED,
    0.0,
    &[0.0],
);

/// The AO radius as a fraction of the scene's diagonal, with a technique's default and sweep.
pub const fn ao_reach(default: f32, sweep: &'static [f32]) -> Knob {
    number(
        "ao-reach",
        "AO radius as a fraction of the scene's bounding-box diagonal, when --ao-radius is 0 (rt: \
         0.1, ≥ 10 makes every hit occlude fully, the sky's true visibility; sao, gtao: 0.05, about \
         the seed's 1.8 m in Sponza's 40 m)",
        1e-4,
        UNBOUNDED,
        default,
        sweep,
    )
}

impl Radius {
    /// The radius of the knobs `ao-radius` (0: none) and `ao-reach`.
    pub fn of(k: &super::Knobs) -> Radius {
        let r = k.number("ao-radius");
        Radius { radius: (r > 0.0).then_some(r), reach: k.number("ao-reach") }
    }
}
