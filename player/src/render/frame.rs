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
use crate::error::{Exit, PlayError, PlayResult};
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
    /// Each pass's name and the milliseconds its constructor (mostly pipeline creation) took
    /// on its own thread, in frame order.
    pub build_ms: Vec<(&'static str, f64)>,
}

/// What the passes of a frame are specialised for: the scene's lights.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SceneLights {
    /// How many analytic lights the scene has.
    pub count: usize,
    /// Whether one of them is a rect light (the direct pass leaves their code out otherwise).
    pub rect: bool,
}

impl SceneLights {
    /// The lights of `manifest`.
    pub fn of(manifest: &kiln_format::Manifest) -> SceneLights {
        SceneLights {
            count: manifest.lights.len(),
            rect: manifest
                .lights
                .iter()
                .any(|l| matches!(l.kind, kiln_format::manifest::LightKind::Rect { .. })),
        }
    }
}

/// Builds the passes `techniques` need, in frame order, for a scene of `lights` whose texel
/// buffer is decoded as `decode` says.
fn passes(
    gpu: &Gpu,
    techniques: &Techniques,
    scene_lights: SceneLights,
    decode: TexelDecode,
) -> PlayResult<Vec<(Box<dyn Pass>, f64)>> {
    let lights = scene_lights.count;
    // Each pass builds its pipelines on a thread of its own: a driver compiles a call's
    // pipelines one after another, and on a cold cache the default frame's took 350 ms in a row
    // on the H100.
    let mut makers: Vec<Maker<'_>> = Vec::new();
    {
        match techniques.gbuffer {
            GBuffer::Raster => makers.push(maker(move || GBufferPass::new(gpu))),
            GBuffer::Visibility => {
                makers.push(maker(move || VisibilityPass::new(gpu)));
                makers.push(maker(move || ResolvePass::new(gpu, decode)));
            }
        }
        if techniques.shadows.traced().is_some() {
            makers.push(maker(move || RtShadowsPass::new(gpu, techniques.shadows, lights, decode)));
        }
        // The depth pyramid, for screen-space AO and GI (GI's with normals, reduced as it says).
        let screen_ao = matches!(techniques.ao, Ao::Sao { .. } | Ao::Gtao { .. });
        // Levels: GI gathers up to the top; SAO's samples read up to level 5; GTAO reads level 0.
        let ao_top = if matches!(techniques.ao, Ao::Sao { .. }) { sao::TOP_LEVEL } else { 0 };
        if let Gi::Ssgi { voting, .. } = techniques.gi {
            let reduction = if voting { Reduction::Voting } else { Reduction::Nearest };
            makers.push(maker(move || DepthPyramidPass::new(gpu, reduction, true, depth_pyramid::TOP)));
        } else if screen_ao {
            makers.push(maker(move || DepthPyramidPass::new(gpu, Reduction::Nearest, false, ao_top)));
        }
        match techniques.ao {
            Ao::None => {}
            Ao::Rt { .. } => makers.push(maker(move || RtAoPass::new(gpu, decode))),
            Ao::Sao { .. } | Ao::Gtao { .. } => {
                let ao = techniques.ao;
                makers.push(maker(move || {
                    if let Ao::Sao { .. } = ao { sao::pass(gpu, ao) } else { gtao::pass(gpu, ao) }
                }));
            }
        }
        // The lit pyramid (the previous frame's radiance), for screen-space reflections and GI:
        // made once, before either reads it.
        if matches!(techniques.reflections, Reflections::Ssr { .. })
            || matches!(techniques.gi, Gi::Ssgi { .. })
        {
            makers.push(maker(move || LitPyramidPass::new(gpu)));
        }
        match techniques.reflections {
            Reflections::None => {}
            Reflections::Rt { resolution, .. } => {
                makers.push(maker(move || RtReflectionsPass::new(gpu, resolution, lights, decode)))
            }
            Reflections::Ssr { .. } => {
                makers.push(maker(move || HizPass::new(gpu)));
                makers.push(maker(move || SsrPass::new(gpu, techniques.reflections)));
            }
        }
        match techniques.gi {
            Gi::Rt { .. } => makers.push(maker(move || RtGiPass::new(gpu, spirv::RT_GI, decode))),
            Gi::LineSpace { structure, .. } => {
                let code = match structure {
                    GiStructure::Pnmt => spirv::RT_GI_LINESPACE_PNMT,
                    GiStructure::Candidates => spirv::RT_GI_LINESPACE_CANDIDATES,
                    GiStructure::Preillum => spirv::RT_GI_LINESPACE_PREILLUM,
                };
                makers.push(maker(move || RtGiPass::with_line_space(gpu, code, decode)));
            }
            Gi::Ssgi { .. } => makers.push(maker(move || SsgiPass::new(gpu, techniques.gi))),
            Gi::None => {}
        }
        if let Some(frames) = techniques.reprojected_rays() {
            makers.push(maker(move || RtHistoryPass::new(gpu, techniques, lights, frames)));
        }
        makers.push(maker(move || DirectPass::new(gpu, techniques, scene_lights.rect)));
        match techniques.media {
            Media::None => {}
            Media::March { steps } => makers.push(maker(move || MediaMarchPass::new(gpu, steps))),
            Media::Mitchell { samples, resolution, exposure } => {
                makers.push(maker(move || MitchellPass::new(gpu, samples, resolution, exposure)))
            }
            Media::Sousa { taps, resolution, brightness } => {
                makers.push(maker(move || SousaPass::new(gpu, taps, resolution, brightness)))
            }
            Media::Toth { samples, block, phase } => {
                makers.push(maker(move || TothPass::new(gpu, samples, block, phase)))
            }
        }
        if let Aa::Taa { frames, luma_weights } = techniques.aa {
            makers.push(maker(move || TaaPass::new(gpu, frames, luma_weights)));
        }
        makers.push(maker(move || TonemapPass::new(gpu)));
    }
    let results: Vec<PlayResult<(Box<dyn Pass>, f64)>> = std::thread::scope(|s| {
        let threads: Vec<_> = makers
            .into_iter()
            .map(|m| {
                s.spawn(move || {
                    let t = std::time::Instant::now();
                    m().map(|p| (p, t.elapsed().as_secs_f64() * 1e3))
                })
            })
            .collect();
        threads
            .into_iter()
            .map(|t| {
                t.join().unwrap_or_else(|_| Err(PlayError::new(Exit::Gpu, "pipeline creation panicked")))
            })
            .collect()
    });
    let mut made = Vec::with_capacity(results.len());
    let mut failed = None;
    for r in results {
        match r {
            Ok(p) => made.push(p),
            Err(e) => failed = failed.or(Some(e)),
        }
    }
    if let Some(e) = failed {
        for (p, _) in &mut made {
            p.destroy(gpu);
        }
        return Err(e);
    }
    Ok(made)
}

/// A pass to make: its constructor, run on a thread of its own by [`passes`].
type Maker<'a> = Box<dyn FnOnce() -> PlayResult<Box<dyn Pass>> + Send + 'a>;

fn maker<'a, P: Pass + 'static>(make: impl FnOnce() -> PlayResult<P> + Send + 'a) -> Maker<'a> {
    Box::new(move || Ok(Box::new(make()?) as Box<dyn Pass>))
}

fn make_images(gpu: &Gpu, passes: &[Box<dyn Pass>], width: u32, height: u32) -> PlayResult<FrameImages> {
    let made: Vec<(TargetDecl, ImageDesc)> = passes.iter().flat_map(|p| p.targets(width, height)).collect();
    let bound: Vec<TargetDecl> = passes.iter().flat_map(|p| p.binds()).collect();
    FrameImages::new(gpu, width, height, &made, &bound)
}

impl Frame {
    /// The passes of `techniques` and their images at `width` × `height`, for a scene of
    /// `lights` whose texel buffer `decode` reads (known from the file's tables before
    /// its sections upload: the pipelines are built while the scene uploads). On failure
    /// everything made is released.
    pub fn new(
        gpu: &Gpu,
        techniques: &Techniques,
        lights: SceneLights,
        decode: TexelDecode,
        width: u32,
        height: u32,
    ) -> PlayResult<Frame> {
        let (mut passes, build_ms): (Vec<_>, Vec<_>) = passes(gpu, techniques, lights, decode)?
            .into_iter()
            .map(|(p, ms)| {
                let name = p.name();
                (p, (name, ms))
            })
            .unzip();
        match make_images(gpu, &passes, width, height) {
            Ok(images) => Ok(Frame { passes, images, decode, build_ms }),
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
