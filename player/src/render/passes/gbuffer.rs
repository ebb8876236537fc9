//! The raster G-buffer (`shaders/gbuffer/gbuffer.{vert,frag}`): every material attribute
//! rasterised into five targets and a reversed-Z depth buffer. Also declares the G-buffer
//! targets every later pass reads, whichever pass makes them.

use crate::gpu::vk;

use super::materials::{SceneDraws, see_through};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Gpu, GraphicsPipeline, ImageDesc, Landing, Use};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// Usage of the G-buffer's colour targets: attachments of the raster pass, storage of the
/// visibility resolve, sampled by the passes after them.
const COLOR_USAGE: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::COLOR_ATTACHMENT.as_raw()
        | vk::ImageUsageFlags::SAMPLED.as_raw()
        | vk::ImageUsageFlags::STORAGE.as_raw(),
);

/// A G-buffer colour target (attachment, storage, sampled).
pub const fn color(name: &'static str, format: vk::Format) -> TargetDecl {
    TargetDecl { name, format, usage: COLOR_USAGE, array: false }
}

/// Octahedral shading normal.
pub const NORMAL: TargetDecl = color("gbuffer normal", vk::Format::R16G16_SNORM);
/// Base colour, sRGB-encoded in a UNORM image.
pub const ALBEDO: TargetDecl = color("gbuffer albedo", vk::Format::R8G8B8A8_UNORM);
/// Metallic, roughness, diffuse-only, occlusion.
pub const MATERIAL: TargetDecl = color("gbuffer material", vk::Format::R8G8B8A8_UNORM);
/// Emitted radiance.
pub const EMISSION: TargetDecl = color("gbuffer emission", vk::Format::R16G16B16A16_SFLOAT);
/// Triangle + 1 in draw order (0: nothing drawn), the visibility buffer.
pub const TRIANGLE: TargetDecl = color("gbuffer triangle", vk::Format::R32_UINT);
/// Reversed-Z depth.
pub const DEPTH: TargetDecl = TargetDecl {
    name: "depth",
    format: vk::Format::D32_SFLOAT,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
    ),
    array: false,
};

/// The G-buffer's colour targets in attachment order (see `shaders/gbuffer/gbuffer.frag`).
pub const COLORS: [TargetDecl; 5] = [NORMAL, ALBEDO, MATERIAL, EMISSION, TRIANGLE];

/// Every G-buffer target sampled by a later pass.
pub fn sampled(targets: &[TargetDecl]) -> Vec<(TargetDecl, Access)> {
    targets.iter().map(|t| (*t, Access::Read(Use::SAMPLED))).collect()
}

/// The raster G-buffer pass.
#[derive(Debug)]
pub struct GBufferPass {
    pipeline: GraphicsPipeline,
    draws: SceneDraws,
    /// Whether see-through surfaces are left to the see-through layer.
    opaque_only: bool,
}

impl GBufferPass {
    /// Builds the pipeline; with `opaque_only`, see-through surfaces are not drawn (the
    /// see-through layer draws them).
    pub fn new(gpu: &Gpu, opaque_only: bool) -> PlayResult<GBufferPass> {
        let draws = SceneDraws::new(gpu)?;
        let formats = COLORS.map(|c| c.format);
        let pipeline = draws.pipeline(
            gpu,
            spirv::shader!("gbuffer/gbuffer.frag"),
            &formats,
            DEPTH.format,
            false,
            Landing::Nearest,
        )?;
        Ok(GBufferPass { pipeline, draws, opaque_only })
    }
}

impl Pass for GBufferPass {
    fn name(&self) -> &'static str {
        "gbuffer"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        COLORS.iter().chain([&DEPTH]).map(|t| (*t, t.sized(width, height, 1))).collect()
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.draws.bind(gpu, shared)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let mut io: Vec<(TargetDecl, Access)> =
            COLORS.iter().map(|t| (*t, Access::Write(Use::COLOR))).collect();
        io.push((DEPTH, Access::Write(Use::DEPTH)));
        ctx.images.access(ctx.rec, &io);
        let colors: Vec<_> = COLORS.iter().map(|t| ctx.images.get(t)).collect();
        ctx.rec.begin_rendering(&colors, ctx.images.get(&DEPTH), true);
        let opaque_only = self.opaque_only;
        self.draws.draw(ctx.rec, ctx.scene, |m| (!opaque_only || !see_through(m)).then_some(&self.pipeline));
        ctx.rec.end_rendering();
    }
}
