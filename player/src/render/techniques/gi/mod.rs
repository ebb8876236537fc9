//! Indirect diffuse light: what replaces the sky's diffuse ambient.

use super::knobs::{Knob, count};
use super::techniques;
use crate::render::passes::rt_gi;
use crate::render::passes::rt_history::{Accumulated, Kind};

techniques! {
    /// Indirect diffuse light.
    Gi for Gi, default none::Off;
    none => Off,
    rt => Rt,
    linespace => LineSpace,
    ssgi => Ssgi,
}

/// Bounces of the path-traced GI techniques.
pub const GI_BOUNCES: Knob = count(
    "gi-bounces",
    "bounces of indirect light after the visible surface (1: the sky, emissive surfaces and \
     the light the first surface hit receives directly; each more adds one bounce)",
    1.0,
    8.0,
    1.0,
    &[1.0, 2.0],
);

/// The GI image the reprojected accumulation carries (every path-traced technique's).
fn accumulated() -> Option<Accumulated> {
    let histories = ["rt gi history a", "rt gi history b"];
    Some(Accumulated::new(rt_gi::GI, histories, Kind::Four, 1, 1))
}

impl Gi {
    /// The bounce count of a path-traced technique.
    pub fn bounces(&self) -> Option<u32> {
        match *self {
            Gi::Rt(rt::Rt { bounces }) | Gi::LineSpace(linespace::LineSpace { bounces, .. }) => Some(bounces),
            Gi::Off(_) | Gi::Ssgi(_) => None,
        }
    }
}
