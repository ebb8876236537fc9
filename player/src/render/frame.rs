//! Wires the passes of a run: each effect's technique adds its passes at their [`Stage`]
//! ([`FrameBuild`]), the shared prerequisites (depth and lit pyramids) are made once for all
//! their readers, and the passes run in stage order; the images they make and bind.
//!
//! Frame order: [`Stage`]'s.

use super::graph::{FrameImages, TargetDecl};
use super::passes::Pass;
use super::passes::depth_pyramid::{DepthPyramidPass, Reduction};
use super::passes::direct::DirectPass;
use super::passes::lit_pyramid::LitPyramidPass;
use super::passes::see_through::{SeeThroughComposite, SeeThroughRaster};
use super::passes::tonemap::TonemapPass;
use super::techniques::{Effect, Techniques};
use super::texels::TexelDecode;
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Gpu, ImageDesc};

/// The passes of a run and the images of the current size. Dropping it releases both: the GPU
/// must be done with them (the owner of a frame that rendered waits for the GPU first).
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
    /// The passes a frame without history records a second time, right after the direct pass
    /// (the last of them): the lit pyramid, made now from the radiance this frame lit, the
    /// passes that read it (screen-space reflections and GI) and what reads theirs, then the
    /// direct pass again. Without it the first frame's screen-space passes gather nothing and
    /// show the split-sum fallback (pica_pica's probes preset: HDR-FLIP 0.0639 at one frame,
    /// 0.0603 from the second on). Empty when nothing reads the lit pyramid.
    pub again: Vec<usize>,
}

/// What the passes of a frame are specialised for: the scene's lights and whether it has
/// see-through surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SceneTraits {
    /// How many analytic lights the scene has.
    pub lights: usize,
    /// Whether one of them is a rect light (the direct pass leaves their code out otherwise).
    pub rect_lights: bool,
    /// Whether the scene has triangles of a see-through material
    /// ([`kiln_format::sections::GpuMaterial::see_through`]): the G-buffer then leaves those
    /// surfaces out and the see-through layer draws them over the lit frame
    /// ([`super::passes::see_through`]).
    pub see_through: bool,
}

impl SceneTraits {
    /// The traits of a scene with `manifest`, and see-through triangles where `see_through`.
    pub fn of(manifest: &kiln_format::Manifest, see_through: bool) -> SceneTraits {
        SceneTraits {
            lights: manifest.lights.len(),
            rect_lights: manifest
                .lights
                .iter()
                .any(|l| matches!(l.kind, kiln_format::manifest::LightKind::Rect { .. })),
            see_through,
        }
    }
}

/// Where a pass runs in the frame: stages run in this order, the passes of one stage in the
/// order they were added (effects add theirs in [`Effect::ALL`] order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Stage {
    /// The G-buffer.
    GBuffer,
    /// Ray-traced shadows.
    Shadows,
    /// The depth pyramid (screen-space AO and GI), made once for every reader.
    DepthPyramid,
    /// Ambient occlusion.
    Ao,
    /// The lit pyramid (the previous frame's radiance: screen-space reflections and GI), made
    /// once, before either reads it and before the direct pass overwrites the radiance.
    LitPyramid,
    /// Reflections.
    Reflections,
    /// Global illumination.
    Gi,
    /// Direct light of emissive surfaces.
    Emitters,
    /// The ray-traced passes' reprojected accumulation.
    Accumulate,
    /// Denoising of the ray-traced signals.
    Denoise,
    /// Direct light and composition.
    Direct,
    /// The see-through layer over the lit frame.
    SeeThrough,
    /// Participating media.
    Media,
    /// Temporal anti-aliasing's resolve.
    Resolve,
    /// Tone mapping.
    Tonemap,
}

/// What the depth pyramid's readers ask of it; the frame makes one that serves them all.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct PyramidRequest {
    reduction: Reduction,
    normals: bool,
    top: u32,
}

/// The passes of a frame being gathered from its techniques ([`crate::render::techniques::Technique::passes`]).
pub struct FrameBuild<'a> {
    /// The device the passes are built on.
    pub gpu: &'a Gpu,
    /// Every effect's technique.
    pub techniques: &'a Techniques,
    /// What the scene holds that the passes are specialised for.
    pub scene: SceneTraits,
    /// How passes that read the texel buffer decode it.
    pub decode: TexelDecode,
    makers: Vec<(Stage, Maker<'a>)>,
    depth_pyramid: Option<PyramidRequest>,
    lit_pyramid: bool,
}

impl std::fmt::Debug for FrameBuild<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameBuild").field("passes", &self.makers.len()).finish()
    }
}

impl<'a> FrameBuild<'a> {
    /// Adds a pass at `stage`, made by `make` (on a thread of its own).
    pub fn add<P: Pass + 'static>(&mut self, stage: Stage, make: impl FnOnce() -> PlayResult<P> + Send + 'a) {
        self.makers.push((stage, Box::new(move || Ok(Box::new(make()?) as Box<dyn Pass>))));
    }

    /// Asks for the depth pyramid up to level `top`, reduced as `reduction` says (voting wins
    /// over nearest), with normals when `normals`.
    pub fn depth_pyramid(&mut self, reduction: Reduction, normals: bool, top: u32) {
        let r = self.depth_pyramid.get_or_insert(PyramidRequest { reduction, normals, top });
        if reduction == Reduction::Voting {
            r.reduction = Reduction::Voting;
        }
        r.normals |= normals;
        r.top = r.top.max(top);
    }

    /// Asks for the lit pyramid.
    pub fn lit_pyramid(&mut self) {
        self.lit_pyramid = true;
    }
}

/// Builds the passes `techniques` need, in frame order, for a `scene` whose texel buffer is
/// decoded as `decode` says.
fn passes(
    gpu: &Gpu,
    techniques: &Techniques,
    scene: SceneTraits,
    decode: TexelDecode,
) -> PlayResult<Vec<Made>> {
    let mut frame = FrameBuild {
        gpu,
        techniques,
        scene,
        decode,
        makers: Vec::new(),
        depth_pyramid: None,
        lit_pyramid: false,
    };
    for effect in Effect::ALL {
        techniques.get(effect).passes(&mut frame);
    }
    if let Some(PyramidRequest { reduction, normals, top }) = frame.depth_pyramid {
        frame.add(Stage::DepthPyramid, move || DepthPyramidPass::new(gpu, reduction, normals, top));
    }
    if frame.lit_pyramid {
        frame.add(Stage::LitPyramid, move || LitPyramidPass::new(gpu));
    }
    frame.add(Stage::Direct, move || DirectPass::new(gpu, techniques, scene.rect_lights));
    if scene.see_through {
        // After the G-buffer technique's passes (a stage keeps the order passes were added in):
        // the layer is drawn in front of the opaque depth they leave.
        frame.add(Stage::GBuffer, move || SeeThroughRaster::new(gpu));
        let media = techniques.dims_surfaces();
        frame.add(Stage::SeeThrough, move || DirectPass::see_through(gpu, media, scene.rect_lights));
        frame.add(Stage::SeeThrough, move || SeeThroughComposite::new(gpu));
    }
    frame.add(Stage::Tonemap, move || TonemapPass::new(gpu));
    let mut makers = frame.makers;
    // Stable: a stage's passes keep the order they were added in.
    makers.sort_by_key(|(stage, _)| *stage);
    // Each pass builds its pipelines on a thread of its own: a driver compiles a call's
    // pipelines one after another, and on a cold cache the default frame's took 350 ms in a row
    // on the H100.
    // Each thread hands back what it made; on an error, the passes the others made are dropped
    // here (none is used by the GPU yet).
    let results: Vec<PlayResult<Made>> = std::thread::scope(|s| {
        let threads: Vec<_> = makers
            .into_iter()
            .map(|(stage, m)| {
                s.spawn(move || {
                    let t = std::time::Instant::now();
                    m().map(|p| (stage, p, t.elapsed().as_secs_f64() * 1e3))
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
    results.into_iter().collect()
}

/// A pass made: its stage, the pass and the milliseconds its constructor took.
type Made = (Stage, Box<dyn Pass>, f64);

/// A pass to make: its constructor, run on a thread of its own by [`passes`].
type Maker<'a> = Box<dyn FnOnce() -> PlayResult<Box<dyn Pass>> + Send + 'a>;

/// [`Frame::again`] of `passes` (in frame order, at `stages`).
fn again(stages: &[Stage], passes: &[Box<dyn Pass>]) -> Vec<usize> {
    let (Some(lit), Some(direct)) = (
        stages.iter().position(|&s| s == Stage::LitPyramid),
        stages.iter().position(|&s| s == Stage::Direct),
    ) else {
        return Vec::new();
    };
    // What a pass makes, by name (the size does not change which).
    let made =
        |p: &dyn Pass| -> Vec<&'static str> { p.targets(1, 1).into_iter().map(|(t, _)| t.name).collect() };
    let mut fresh = made(passes[lit].as_ref());
    let mut again = vec![lit];
    for (i, p) in passes.iter().enumerate().take(direct).skip(lit + 1) {
        if p.binds().iter().any(|t| fresh.contains(&t.name)) {
            fresh.extend(made(p.as_ref()));
            again.push(i);
        }
    }
    if again.len() == 1 {
        return Vec::new();
    }
    again.push(direct);
    // The see-through layer goes over the radiance the direct pass lit again.
    again.extend((direct + 1..stages.len()).filter(|&i| stages[i] == Stage::SeeThrough));
    again
}

fn make_images(gpu: &Gpu, passes: &[Box<dyn Pass>], width: u32, height: u32) -> PlayResult<FrameImages> {
    let made: Vec<(TargetDecl, ImageDesc)> = passes.iter().flat_map(|p| p.targets(width, height)).collect();
    let bound: Vec<TargetDecl> = passes.iter().flat_map(|p| p.binds()).collect();
    FrameImages::new(gpu, width, height, &made, &bound)
}

impl Frame {
    /// The passes of `techniques` and their images at `width` × `height`, for a `scene` whose
    /// texel buffer `decode` reads (known from the file's tables before
    /// its sections upload: the pipelines are built while the scene uploads). On failure
    /// everything made is released (dropped).
    pub fn new(
        gpu: &Gpu,
        techniques: &Techniques,
        scene: SceneTraits,
        decode: TexelDecode,
        width: u32,
        height: u32,
    ) -> PlayResult<Frame> {
        let made = passes(gpu, techniques, scene, decode)?;
        let stages: Vec<Stage> = made.iter().map(|(stage, _, _)| *stage).collect();
        let (passes, build_ms): (Vec<_>, Vec<_>) = made
            .into_iter()
            .map(|(_, p, ms)| {
                let name = p.name();
                (p, (name, ms))
            })
            .unzip();
        let again = again(&stages, &passes);
        let images = make_images(gpu, &passes, width, height)?;
        Ok(Frame { passes, images, decode, build_ms, again })
    }

    /// Remakes the images for a new size (the GPU must be idle); the caller rebinds.
    pub fn resize(&mut self, gpu: &Gpu, width: u32, height: u32) -> PlayResult {
        // The old images go before the new ones are made: both at once could exceed the
        // memory either needs.
        drop(std::mem::take(&mut self.images));
        self.images = make_images(gpu, &self.passes, width, height)?;
        Ok(())
    }
}
