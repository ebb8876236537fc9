//! The visibility-buffer resolve (`shaders/gbuffer/resolve.comp`): each pixel's triangle and
//! the pixel ray give the surface point; materials are evaluated there in compute (trilinear
//! filtering from the texel buffer's mip chains, ray-differential footprints) into the same
//! targets the raster G-buffer writes.

use super::gbuffer::{ALBEDO, DEPTH, EMISSION, MATERIAL, NORMAL, TRIANGLE};
use super::kernel::Kernel;
use super::{FrameCtx, Pass, Shared};
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Binding, BindingKind, Gpu, ImageDesc, Use, Write};
use crate::render::TexelDecode;
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The targets the resolve writes.
const OUTPUTS: [TargetDecl; 4] = [NORMAL, ALBEDO, MATERIAL, EMISSION];

/// The resolve pass.
#[derive(Debug)]
pub struct ResolvePass(Kernel);

impl ResolvePass {
    /// Builds the pipeline for a texel buffer that `decode` reads.
    pub fn new(gpu: &Gpu, decode: TexelDecode) -> PlayResult<ResolvePass> {
        use BindingKind::*;
        let mut bindings = vec![Binding::one(Uniform)];
        bindings.extend([Binding::one(Storage); 7]);
        bindings.extend([Binding::one(StorageImage); 5]);
        bindings.push(Binding::one(Sampled));
        Ok(ResolvePass(Kernel::reading_texels(
            gpu,
            &bindings,
            spirv::shader!("gbuffer/resolve.comp"),
            0,
            decode,
        )?))
    }
}

impl Pass for ResolvePass {
    fn name(&self) -> &'static str {
        "resolve"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        OUTPUTS.iter().map(|t| (*t, t.sized(width, height, 1))).collect()
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![TRIANGLE, DEPTH]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let scene = shared.scene;
        let r = scene.reference.as_ref().ok_or_else(|| {
            PlayError::new(
                Exit::Gpu,
                "the visibility resolve needs the scene buffers, which were not uploaded",
            )
        })?;
        let img = |t: &TargetDecl| shared.images.get(t).view;
        self.0.write(
            gpu,
            &[
                Write::Buffer(0, shared.frame_ubo),
                Write::Buffer(1, &scene.vertices),
                Write::Buffer(2, &scene.attributes),
                Write::Buffer(3, &scene.indices),
                Write::Buffer(4, &r.raster_materials),
                Write::Buffer(5, &r.materials),
                Write::Buffer(6, &r.texels),
                Write::Buffer(7, &r.textures),
                Write::StorageImage(8, img(&TRIANGLE)),
                Write::StorageImage(9, img(&NORMAL)),
                Write::StorageImage(10, img(&ALBEDO)),
                Write::StorageImage(11, img(&MATERIAL)),
                Write::StorageImage(12, img(&EMISSION)),
                Write::Sampled(13, vec![(img(&DEPTH), scene.nearest_clamp)]),
            ],
        )
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let mut io: Vec<(TargetDecl, Access)> =
            OUTPUTS.iter().map(|t| (*t, Access::Write(Use::STORAGE))).collect();
        io.push((TRIANGLE, Access::ReadWrite(Use::STORAGE)));
        io.push((DEPTH, Access::Read(Use::SAMPLED)));
        ctx.images.access(ctx.rec, &io);
        self.0.dispatch(ctx.rec, &[], ctx.images.width, ctx.images.height);
    }
}
