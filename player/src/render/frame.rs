//! Wires the passes of a run: which passes the chosen techniques need, in frame order, and the
//! images they make and bind.
//!
//! Frame order: G-buffer (raster, or visibility raster + resolve) → ray-traced shadows, the
//! depth pyramid (for screen-space AO or GI), AO (ray-traced, SAO or GTAO), reflections
//! (ray-traced, or the Hi-Z pyramid and SSR, which reads the previous frame's radiance before the
//! direct pass overwrites it), GI (ray-traced, or the lit pyramid and screen-space GI) (each when
//! chosen) → the
//! ray-traced passes' reprojected accumulation (with `--aa reproject` or `taa`) → direct light
//! and composition → participating media (march, mitchell, sousa or toth, when chosen) →
//! temporal anti-aliasing (when chosen) → tone mapping.

use super::graph::{FrameImages, TargetDecl};
use super::passes::Pass;
use super::passes::depth_pyramid::{self, DepthPyramidPass, Reduction};
use super::passes::direct::DirectPass;
use super::passes::gbuffer::GBufferPass;
use super::passes::hiz::HizPass;
use super::passes::lit_pyramid::LitPyramidPass;
use super::passes::media::MediaMarchPass;
use super::passes::mitchell::MitchellPass;
use super::passes::resolve::ResolvePass;
use super::passes::rt_ao::RtAoPass;
use super::passes::rt_gi::RtGiPass;
use super::passes::rt_history::RtHistoryPass;
use super::passes::rt_reflections::RtReflectionsPass;
use super::passes::rt_shadows::RtShadowsPass;
use super::passes::sousa::SousaPass;
use super::passes::ssgi::SsgiPass;
use super::passes::ssr::SsrPass;
use super::passes::taa::TaaPass;
use super::passes::tonemap::TonemapPass;
use super::passes::toth::TothPass;
use super::passes::visibility::VisibilityPass;
use super::passes::{gtao, sao};
use super::spirv;
use super::technique::{Aa, Ao, GBuffer, Gi, GiStructure, Media, Reflections, Techniques};
use super::texels::TexelDecode;
use crate::error::PlayResult;
use crate::gpu::{Gpu, ImageDesc};

/// The passes of a run and the images of the current size.
#[derive(Debug)]
pub struct Frame {
    /// The passes, in order.
    pub passes: Vec<Box<dyn Pass>>,
    /// Their images.
    pub images: FrameImages,
    /// How the passes that read the texel buffer decode it.
    pub decode: TexelDecode,
}

/// Builds the passes `techniques` need, in frame order, for a scene of `lights` lights whose
/// texel buffer is decoded as `decode` says.
fn passes(
    gpu: &Gpu,
    techniques: &Techniques,
    lights: usize,
    decode: TexelDecode,
) -> PlayResult<Vec<Box<dyn Pass>>> {
    let mut made: Vec<Box<dyn Pass>> = Vec::new();
    let built = (|| -> PlayResult {
        match techniques.gbuffer {
            GBuffer::Raster => made.push(Box::new(GBufferPass::new(gpu)?)),
            GBuffer::Visibility => {
                made.push(Box::new(VisibilityPass::new(gpu)?));
                made.push(Box::new(ResolvePass::new(gpu, decode)?));
            }
        }
        if techniques.shadows.traced().is_some() {
            made.push(Box::new(RtShadowsPass::new(gpu, techniques.shadows, lights, decode)?));
        }
        // The depth pyramid, for screen-space AO and GI (GI's with normals, reduced as it says).
        let screen_ao = matches!(techniques.ao, Ao::Sao { .. } | Ao::Gtao { .. });
        // Levels: GI gathers up to the top; SAO's samples read up to level 5; GTAO reads level 0.
        let ao_top = if matches!(techniques.ao, Ao::Sao { .. }) { sao::TOP_LEVEL } else { 0 };
        if let Gi::Ssgi { voting, .. } = techniques.gi {
            let reduction = if voting { Reduction::Voting } else { Reduction::Nearest };
            made.push(Box::new(DepthPyramidPass::new(gpu, reduction, true, depth_pyramid::TOP)?));
        } else if screen_ao {
            made.push(Box::new(DepthPyramidPass::new(gpu, Reduction::Nearest, false, ao_top)?));
        }
        match techniques.ao {
            Ao::None => {}
            Ao::Rt { .. } => made.push(Box::new(RtAoPass::new(gpu, decode)?)),
            Ao::Sao { .. } | Ao::Gtao { .. } => {
                made.push(Box::new(if let Ao::Sao { .. } = techniques.ao {
                    sao::pass(gpu, techniques.ao)?
                } else {
                    gtao::pass(gpu, techniques.ao)?
                }));
            }
        }
        // The lit pyramid (the previous frame's radiance), for screen-space reflections and GI:
        // made once, before either reads it.
        if matches!(techniques.reflections, Reflections::Ssr { .. })
            || matches!(techniques.gi, Gi::Ssgi { .. })
        {
            made.push(Box::new(LitPyramidPass::new(gpu)?));
        }
        match techniques.reflections {
            Reflections::None => {}
            Reflections::Rt { resolution, .. } => {
                made.push(Box::new(RtReflectionsPass::new(gpu, resolution, lights, decode)?))
            }
            Reflections::Ssr { .. } => {
                made.push(Box::new(HizPass::new(gpu)?));
                made.push(Box::new(SsrPass::new(gpu, techniques.reflections)?));
            }
        }
        match techniques.gi {
            Gi::Rt { .. } => made.push(Box::new(RtGiPass::new(gpu, spirv::RT_GI, decode)?)),
            Gi::LineSpace { structure, .. } => {
                let code = match structure {
                    GiStructure::Pnmt => spirv::RT_GI_LINESPACE_PNMT,
                    GiStructure::Candidates => spirv::RT_GI_LINESPACE_CANDIDATES,
                    GiStructure::Preillum => spirv::RT_GI_LINESPACE_PREILLUM,
                };
                made.push(Box::new(RtGiPass::with_line_space(gpu, code, decode)?));
            }
            Gi::Ssgi { .. } => made.push(Box::new(SsgiPass::new(gpu, techniques.gi)?)),
            Gi::None => {}
        }
        if let Some(frames) = techniques.reprojected_rays() {
            made.push(Box::new(RtHistoryPass::new(gpu, techniques, lights, frames)?));
        }
        made.push(Box::new(DirectPass::new(gpu)?));
        match techniques.media {
            Media::None => {}
            Media::March { steps } => made.push(Box::new(MediaMarchPass::new(gpu, steps)?)),
            Media::Mitchell { samples, resolution, exposure } => {
                made.push(Box::new(MitchellPass::new(gpu, samples, resolution, exposure)?))
            }
            Media::Sousa { taps, resolution, brightness } => {
                made.push(Box::new(SousaPass::new(gpu, taps, resolution, brightness)?))
            }
            Media::Toth { samples, block, phase } => {
                made.push(Box::new(TothPass::new(gpu, samples, block, phase)?))
            }
        }
        if let Aa::Taa { frames, luma_weights } = techniques.aa {
            made.push(Box::new(TaaPass::new(gpu, frames, luma_weights)?));
        }
        made.push(Box::new(TonemapPass::new(gpu)?));
        Ok(())
    })();
    if let Err(e) = built {
        for p in &mut made {
            p.destroy(gpu);
        }
        return Err(e);
    }
    Ok(made)
}

fn make_images(gpu: &Gpu, passes: &[Box<dyn Pass>], width: u32, height: u32) -> PlayResult<FrameImages> {
    let made: Vec<(TargetDecl, ImageDesc)> = passes.iter().flat_map(|p| p.targets(width, height)).collect();
    let bound: Vec<TargetDecl> = passes.iter().flat_map(|p| p.binds()).collect();
    FrameImages::new(gpu, width, height, &made, &bound)
}

impl Frame {
    /// The passes of `techniques` and their images at `width` × `height`, for a scene of
    /// `lights` lights whose texel buffer `decode` reads (known from the file's tables before
    /// its sections upload: the pipelines are built while the scene uploads). On failure
    /// everything made is released.
    pub fn new(
        gpu: &Gpu,
        techniques: &Techniques,
        lights: usize,
        decode: TexelDecode,
        width: u32,
        height: u32,
    ) -> PlayResult<Frame> {
        let mut passes = passes(gpu, techniques, lights, decode)?;
        match make_images(gpu, &passes, width, height) {
            Ok(images) => Ok(Frame { passes, images, decode }),
            Err(e) => {
                for p in &mut passes {
                    p.destroy(gpu);
                }
                Err(e)
            }
        }
    }

    /// Remakes the images for a new size (the GPU must be idle); the caller rebinds.
    pub fn resize(&mut self, gpu: &Gpu, width: u32, height: u32) -> PlayResult {
        self.images.destroy(gpu);
        self.images = make_images(gpu, &self.passes, width, height)?;
        Ok(())
    }

    /// Releases passes and images.
    pub fn destroy(&mut self, gpu: &Gpu) {
        for p in &mut self.passes {
            p.destroy(gpu);
        }
        self.images.destroy(gpu);
    }
}
