//! Scalable ambient obscurance as the seed modifies it (`--ao sao`; seed 000 §2.3,
//! `shaders/sao/sao.comp`): N spiral samples of the camera-space depth pyramid
//! ([`super::depth_pyramid`]) and the G-buffer normals per AO pixel, at full or half resolution,
//! then a bilateral blur with depth weights that also upsamples ([`super::ao::ScreenAoPass`]).
//! Deterministic per frame: the AO image is overwritten, never accumulated.

use kiln_format::gpu::ScreenAoConstants;

use super::ao::ScreenAoPass;
use crate::error::PlayResult;
use crate::gpu::Gpu;
use crate::render::spirv;
use crate::render::technique::Ao;

/// The coarsest depth-pyramid level SAO's samples read (`SAO_TOP` in `shaders/sao/sao.comp`;
/// McGuire et al. 2012 stop at 5).
pub const TOP_LEVEL: u32 = 5;

/// The pass of `technique` (an [`Ao::Sao`]).
pub fn pass(gpu: &Gpu, technique: Ao) -> PlayResult<ScreenAoPass> {
    let Ao::Sao { samples, turns, resolution, .. } = technique else {
        unreachable!("the frame builds the SAO pass for --ao sao only")
    };
    let constants =
        ScreenAoConstants { count: samples.max(1), turns, step: resolution.divisor(), ..Default::default() };
    ScreenAoPass::new(gpu, spirv::SAO, constants, technique)
}
