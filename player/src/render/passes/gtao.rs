//! Ground-truth ambient occlusion (`--ao gtao`; Jimenez et al. 2016, "Practical Real-Time
//! Strategies for Accurate Indirect Occlusion"; `shaders/gtao/gtao.comp`): per screen pixel,
//! the cosine-weighted visibility integrated over `slices` screen directions, each between the
//! two horizons found by `steps` samples per side of the depth pyramid's level 0 within the
//! world radius, with the normal projected into the slice; then the screen-space AO's bilateral
//! blur ([`super::ao::ScreenAoPass`]). Full resolution, as Intel's XeGTAO (whose "High" preset is 3
//! slices × 3 steps, the defaults here). Deterministic per frame.

use kiln_format::gpu::ScreenAoConstants;

use super::ao::ScreenAoPass;
use crate::error::PlayResult;
use crate::gpu::Gpu;
use crate::render::spirv;
use crate::render::technique::Ao;

/// The pass of `technique` (an [`Ao::Gtao`]).
pub fn pass(gpu: &Gpu, technique: Ao) -> PlayResult<ScreenAoPass> {
    let Ao::Gtao { slices, steps, .. } = technique else {
        unreachable!("the frame builds the GTAO pass for --ao gtao only")
    };
    let constants =
        ScreenAoConstants { count: slices.max(1), steps: steps.max(1), step: 1, ..Default::default() };
    ScreenAoPass::new(gpu, spirv::GTAO, constants, technique)
}
