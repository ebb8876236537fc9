//! Indirect diffuse light: what replaces the sky's diffuse ambient.

use super::knobs::{Knob, number, whole};
use super::techniques;

techniques! {
    /// Indirect diffuse light.
    Gi for Gi, default none::Off;
    none => Off,
    rt => Rt,
    linespace => LineSpace,
    ssgi => Ssgi,
    probes => Probes,
}

/// Bounces of the path-traced GI techniques.
pub const GI_BOUNCES: Knob = whole(number(
    "gi-bounces",
    "bounces of indirect light after the visible surface (1: the sky, emissive surfaces and \
     the light the first surface hit receives directly; each more adds one bounce)",
    1.0,
    8.0,
    1.0,
    &[1.0, 2.0],
));

/// The least roughness of the surfaces the path-traced GI's paths hit.
pub const GI_REGULARIZE: Knob = number(
    "gi-regularize",
    "the least roughness of the surfaces the GI paths hit (path regularisation): a glossy \
     highlight of a light seen from a diffuse surface is a rare, very bright sample; widening \
     it trades a little gloss in the indirect light for far fewer fireflies (0: unbiased)",
    0.0,
    1.0,
    0.5,
    &[0.0, 0.5],
);

/// The `Technique` methods the path-traced GI techniques share (their settings' `bounces`): ray
/// traced, the GI image accumulated, the bounce count and the regularisation set.
macro_rules! traced_gi {
    () => {
        fn ray_traced(&self) -> bool {
            true
        }

        fn flags(&self) -> u32 {
            kiln_format::gpu::FrameFlags::RT_GI
        }

        fn accumulated(&self, _: usize) -> Option<$crate::render::passes::rt_history::Accumulated> {
            use $crate::render::passes::rt_history::{Accumulated, Kind};
            let histories = ["rt gi history a", "rt gi history b"];
            Some(Accumulated::new($crate::render::passes::rt_gi::GI, histories, Kind::Four, 1, 1))
        }

        fn rays(
            &self,
            _: &$crate::render::techniques::RayScene,
            inputs: &mut $crate::render::techniques::RayInputs,
        ) {
            inputs.rt.gi_bounces = self.bounces;
            inputs.rt.gi_min_roughness = self.regularize;
        }

        fn noisy(&self) -> Option<$crate::render::passes::denoise::Noisy> {
            use $crate::render::passes::denoise::{GI_DENOISED, Noisy};
            // Mean incoming radiance: no albedo in it.
            Some(Noisy { target: $crate::render::passes::rt_gi::GI, output: GI_DENOISED, demodulate: false })
        }
    };
}
use traced_gi;

impl Gi {
    /// The bounce count of a path-traced technique.
    pub fn bounces(&self) -> Option<u32> {
        match *self {
            Gi::Rt(rt::Rt { bounces, .. }) | Gi::LineSpace(linespace::LineSpace { bounces, .. }) => {
                Some(bounces)
            }
            Gi::Off(_) | Gi::Ssgi(_) | Gi::Probes(_) => None,
        }
    }
}
