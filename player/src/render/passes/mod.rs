//! The passes of a frame, one file each. A pass owns its pipelines, set layouts and binding
//! table, the targets it makes, its timestamp name, and declares the targets each of its steps
//! reads and writes; [`super::frame`] chooses the passes of a run from the techniques and
//! [`super::graph`] derives the barriers between them.
//!
//! A pass is built in two steps: [`Pass`] values are made with their pipelines before the
//! scene is resident (pipelines compile while the file uploads), then [`Pass::bind`] points
//! their descriptor sets at the scene and the frame's images (again after every resize).

pub mod ao;
pub mod denoise;
pub mod depth_pyramid;
pub mod direct;
pub mod fxaa;
pub mod gbuffer;

pub mod hiz;
pub mod hybrid;
pub mod kernel;
pub mod lit_pyramid;
pub mod materials;
pub mod media;
pub mod mitchell;
pub mod pathtrace;
pub mod probes;
pub mod resolve;
pub mod rt_ao;
pub mod rt_direct;
pub mod rt_gi;
pub mod rt_history;
pub mod rt_reflections;
pub mod rt_shadows;
pub mod see_through;

pub mod sousa;
pub mod ssgi;
pub mod ssr;
pub mod taa;
pub mod tonemap;
pub mod toth;
pub mod visibility;

use kiln_format::gpu::RtConstants;

use super::dummies::Dummies;
use super::graph::{FrameImages, TargetDecl};
use super::lights::LightPlan;
use crate::error::PlayResult;
use crate::gpu::{Buffer, Gpu, ImageDesc, Recorder};
use crate::scene::GpuScene;

/// What the renderer shares with every pass when binding.
#[derive(Debug)]
pub struct Shared<'a> {
    /// The resident scene.
    pub scene: &'a GpuScene,
    /// The frame constants (`FrameConstants`, uniform).
    pub frame_ubo: &'a Buffer,
    /// The lights (`GpuLight`s, storage).
    pub lights: &'a Buffer,
    /// The bound shadow maps' parameters (`GpuShadow`s, storage).
    pub shadows: &'a Buffer,
    /// Which resident shadow map goes in which slot.
    pub plan: &'a LightPlan,
    /// Placeholder images.
    pub dummies: &'a Dummies,
    /// The frame's images.
    pub images: &'a FrameImages,
}

/// A sampler array's descriptors: (view, sampler) per element.
pub type SampledArray = Vec<(crate::gpu::vk::ImageView, crate::gpu::vk::Sampler)>;

/// The shadow-map sampler arrays (2D, cube) of `MAX_SHADOW_MAPS` elements each, as the light
/// plan binds them: each resident map in its slot, placeholders in the rest.
pub fn shadow_map_arrays(shared: &Shared) -> (SampledArray, SampledArray) {
    let (scene, dummies) = (shared.scene, shared.dummies);
    let near = scene.nearest_clamp;
    let mut maps_2d = vec![(dummies.shadow_2d.view, near); super::MAX_SHADOW_MAPS];
    let mut maps_cube = vec![(dummies.shadow_cube.view, near); super::MAX_SHADOW_MAPS];
    for (slot, &i) in shared.plan.slots_2d.iter().enumerate() {
        maps_2d[slot] = (scene.shadow_maps[i].image.view, near);
    }
    for (slot, &i) in shared.plan.slots_cube.iter().enumerate() {
        maps_cube[slot] = (scene.shadow_maps[i].image.view, near);
    }
    (maps_2d, maps_cube)
}

/// What a pass records with.
#[derive(Debug)]
pub struct FrameCtx<'a, 'r> {
    /// The command buffer.
    pub rec: &'a Recorder<'r>,
    /// The frame's images (barriers go through [`FrameImages::access`]).
    pub images: &'a mut FrameImages,
    /// The resident scene.
    pub scene: &'a GpuScene,
    /// This frame's constants of the ray-traced passes (their push constants).
    pub rt: &'a RtConstants,
    /// The pass is recorded a second time in a frame without history, over the radiance the
    /// direct pass lit in this frame ([`crate::render::frame::Frame::again`]).
    pub again: bool,
    /// Where the see-through surfaces may show this frame ([`see_through::screen_area`]).
    pub see_through_area: crate::gpu::vk::Rect2D,
}

/// One pass of the frame. Dropping it releases what it owns: the GPU must be done with it (the
/// frame's owner waits for the GPU before it drops a frame that was rendered).
pub trait Pass: Send + std::fmt::Debug {
    /// Timestamp name.
    fn name(&self) -> &'static str;

    /// The targets this pass makes at `width` × `height`.
    fn targets(&self, _width: u32, _height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        Vec::new()
    }

    /// Targets its descriptor sets bind that other passes make (or that are placeholders when
    /// none does).
    fn binds(&self) -> Vec<TargetDecl> {
        Vec::new()
    }

    /// Allocates (the first time) and writes its descriptor sets.
    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult;

    /// Records its work, declaring each step's reads and writes first.
    fn record(&mut self, ctx: &mut FrameCtx);
}
