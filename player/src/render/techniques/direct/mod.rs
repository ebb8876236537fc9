//! Direct light of emissive surfaces: the light the emissive triangles (glTF's only area lights:
//! lamps, screens, windows) send to the visible surfaces. The analytic lights are the direct
//! pass's; this effect adds the emitters' light through an image the composition reads.
//!
//! Visibility comes from the shadows technique's choice: shadow rays through the line space with
//! `--shadows linespace` (its `--ls-shadow-test`), through the BVH otherwise, except `--shadows
//! none`, which leaves the emitters' light unshadowed as it does the lights'.

use super::knobs::{Knob, number, whole};
use super::techniques;

techniques! {
    /// Direct light of emissive surfaces.
    Direct for Direct, default restir::Restir;
    none => Off,
    ris => Ris,
    restir => Restir,
}

/// Candidates per pixel and frame.
pub const CANDIDATES: Knob = whole(number(
    "direct-candidates",
    "candidate points on emissive triangles per pixel and frame, one kept by resampled importance \
     sampling (each costs no ray)",
    1.0,
    64.0,
    8.0,
    // 1: plain next-event estimation, the many-light baseline.
    &[1.0, 4.0, 16.0],
));

/// The `Technique` methods the direct-light techniques share (their settings' `candidates`,
/// `spatial` and `temporal`): ray traced, the direct-light image accumulated, the constants set,
/// the pass added.
macro_rules! traced_direct {
    () => {
        fn ray_traced(&self) -> bool {
            true
        }

        fn flags(&self) -> u32 {
            kiln_format::gpu::FrameFlags::RT_DIRECT
        }

        fn accumulated(&self, _: usize) -> Option<$crate::render::passes::rt_history::Accumulated> {
            use $crate::render::passes::rt_history::{Accumulated, Kind};
            let histories = ["rt direct history a", "rt direct history b"];
            Some(Accumulated::new($crate::render::passes::rt_direct::DIRECT, histories, Kind::Four, 1, 1))
        }

        fn rays(
            &self,
            _: &$crate::render::techniques::RayScene,
            inputs: &mut $crate::render::techniques::RayInputs,
        ) {
            inputs.rt.direct_candidates = self.candidates;
            inputs.rt.direct_spatial = self.spatial;
            inputs.rt.direct_temporal = self.temporal;
        }

        fn noisy(&self) -> Option<$crate::render::passes::denoise::Noisy> {
            use $crate::render::passes::denoise::{DIRECT_DENOISED, Noisy};
            // Outgoing radiance: the BRDF, and so the albedo, is in it.
            Some(Noisy {
                target: $crate::render::passes::rt_direct::DIRECT,
                output: DIRECT_DENOISED,
                demodulate: true,
            })
        }

        fn passes<'a>(&'a self, frame: &mut $crate::render::frame::FrameBuild<'a>) {
            use $crate::render::frame::Stage;
            use $crate::render::passes::rt_direct::{RtDirectPass, Visibility};
            use $crate::render::techniques::Effect;
            let shadows = frame.techniques.get(Effect::Shadows);
            let visibility = match shadows.line_space_visibility() {
                Some(exact) => Visibility::LineSpace { exact },
                None => Visibility::Bvh,
            };
            let (gpu, decode) = (frame.gpu, frame.decode);
            frame.add(Stage::Emitters, move || RtDirectPass::new(gpu, decode, visibility));
        }
    };
}
use traced_direct;
