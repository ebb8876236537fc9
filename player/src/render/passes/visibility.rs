//! The visibility-buffer raster pass (`shaders/gbuffer/visibility*.frag`): only the triangle
//! under each pixel and depth are rasterised; [`super::resolve`] evaluates the materials.

use kiln_format::sections::MaterialFlags;

use super::gbuffer::{DEPTH, TRIANGLE};
use super::materials::{SceneDraws, see_through};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Gpu, GraphicsPipeline, ImageDesc, Landing, Use};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The visibility raster pass.
#[derive(Debug)]
pub struct VisibilityPass {
    /// Opaque one-sided materials: culled in hardware and a shader without `discard`, so the
    /// depth test runs before shading.
    opaque: GraphicsPipeline,
    /// Masked or double-sided materials: the shader decides.
    raster: GraphicsPipeline,
    draws: SceneDraws,
    /// Whether see-through surfaces are left to the see-through layer.
    opaque_only: bool,
}

impl VisibilityPass {
    /// Builds the pipelines; with `opaque_only`, see-through surfaces are not drawn (the
    /// see-through layer draws them).
    pub fn new(gpu: &Gpu, opaque_only: bool) -> PlayResult<VisibilityPass> {
        let draws = SceneDraws::new(gpu)?;
        let colors = [TRIANGLE.format];
        let build = |fragment: &[u8], cull: bool| {
            draws.pipeline(gpu, fragment, &colors, DEPTH.format, cull, Landing::Nearest)
        };
        let opaque = build(spirv::shader!("gbuffer/visibility_opaque.frag"), true)?;
        let raster = build(spirv::shader!("gbuffer/visibility.frag"), false)?;
        Ok(VisibilityPass { opaque, raster, draws, opaque_only })
    }
}

impl Pass for VisibilityPass {
    fn name(&self) -> &'static str {
        "gbuffer"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        [TRIANGLE, DEPTH].iter().map(|t| (*t, t.sized(width, height, 1))).collect()
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.draws.bind(gpu, shared)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        ctx.images
            .access(ctx.rec, &[(TRIANGLE, Access::Write(Use::COLOR)), (DEPTH, Access::Write(Use::DEPTH))]);
        // The visibility buffer is not cleared (a full-screen clear costs as much as a target's
        // writes on GPUs with few raster units): the resolve marks pixels at the far plane empty.
        ctx.rec.begin_rendering(&[ctx.images.get(&TRIANGLE)], ctx.images.get(&DEPTH), false);
        self.draws.draw(ctx.rec, ctx.scene, |m| {
            if self.opaque_only && see_through(m) {
                return None;
            }
            let opaque_one_sided = m.flags & MaterialFlags::DOUBLE_SIDED == 0
                && (m.flags >> MaterialFlags::ALPHA_MODE_SHIFT) & 3 != 1;
            Some(if opaque_one_sided { &self.opaque } else { &self.raster })
        });
        ctx.rec.end_rendering();
    }
}
