//! The see-through layer: surfaces that what lies behind shows through — alpha-blended (glTF
//! BLEND) or transmitting (`KHR_materials_transmission`) — drawn over the lit frame instead of
//! into the G-buffer. Before it the raster frame drew them opaque: Khronos ToyCar's windshield
//! hid its cabin, the LightsPunctualLamp's glass shade its bulb, pica_pica's screens what lies
//! behind their dark glass.
//!
//! Where the scene has such materials ([`crate::render::frame::SceneTraits::see_through`]):
//! - the G-buffer (either technique) leaves them out, so that every technique lights the
//!   opaque surfaces behind them;
//! - [`SeeThroughRaster`] draws them into targets of their own, keeping at each pixel the
//!   nearest in front of the opaque depth (`shaders/gbuffer/see_through.frag`), with its
//!   coverage (a blended surface's alpha, else 1), and summing over all of them how much of the
//!   light from straight behind each lets through (a glass shell has two faces);
//! - the direct pass lights that layer ([`super::direct::DirectPass::see_through`]): analytic
//!   lights, the sky or environment, emission; no screen-space or ray-traced input;
//! - [`SeeThroughComposite`] lays it over the frame's radiance: the nearest surface's light
//!   times its coverage, plus the radiance behind times what every surface in front of it lets
//!   through (`shaders/gbuffer/gbuffer.glsl` says how much).
//!
//! Only the nearest see-through surface is lit: those behind it dim the light from behind but
//! reflect nothing. What they let through is the opaque radiance straight behind them (no blur
//! through rough glass, no refraction).

use crate::gpu::vk;

use super::gbuffer::{DEPTH as OPAQUE_DEPTH, color};
use super::kernel::Kernel;
use super::materials::{SceneDraws, see_through};
use super::{FrameCtx, Pass, Shared};
use crate::error::PlayResult;
use crate::gpu::{Binding, BindingKind, Gpu, GraphicsPipeline, ImageDesc, Landing, Use, Write};
use crate::render::graph::{Access, TargetDecl};
use crate::render::spirv;

/// The layer's octahedral shading normal.
pub const NORMAL: TargetDecl = color("see-through normal", vk::Format::R16G16_SNORM);
/// Its base colour, sRGB-encoded.
pub const ALBEDO: TargetDecl = color("see-through albedo", vk::Format::R8G8B8A8_UNORM);
/// Its metallic, roughness, transmission or F0, occlusion.
pub const MATERIAL: TargetDecl = color("see-through material", vk::Format::R8G8B8A8_UNORM);
/// Its emitted radiance and clear coat.
pub const EMISSION: TargetDecl = color("see-through emission", vk::Format::R16G16B16A16_SFLOAT);
/// Its triangle + 1 (0: none).
pub const TRIANGLE: TargetDecl = color("see-through triangle", vk::Format::R32_UINT);
/// Its coverage: a blended surface's alpha, else 1.
/// (Attachment and sampled only: R8 storage images are optional in Vulkan.)
pub const COVERAGE: TargetDecl = TargetDecl {
    name: "see-through coverage",
    format: vk::Format::R8_UNORM,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::COLOR_ATTACHMENT.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
    ),
    array: false,
};
/// Over every see-through surface in front of the opaque one (not only the nearest): the sum
/// of −ln of the share of the light from straight behind it lets through, per channel; what the
/// composition multiplies the radiance behind by is its exponential (additive blending serves
/// for a product that does not depend on the order surfaces are drawn in).
pub const ABSORBED: TargetDecl = TargetDecl {
    name: "see-through absorbed",
    format: vk::Format::R16G16B16A16_SFLOAT,
    usage: vk::ImageUsageFlags::from_raw(
        vk::ImageUsageFlags::COLOR_ATTACHMENT.as_raw() | vk::ImageUsageFlags::SAMPLED.as_raw(),
    ),
    array: false,
};
/// Its reversed-Z depth (0 where no see-through surface lies in front of the opaque one).
pub const DEPTH: TargetDecl = TargetDecl { name: "see-through depth", ..OPAQUE_DEPTH };
/// Its own light (what the direct pass writes for it).
pub const RADIANCE: TargetDecl = TargetDecl {
    name: "see-through radiance",
    format: vk::Format::R32G32B32A32_SFLOAT,
    usage: vk::ImageUsageFlags::STORAGE,
    array: false,
};

/// The nearest surface's colour targets in attachment order (`shaders/gbuffer/gbuffer.glsl`).
const COLORS: [TargetDecl; 6] = [NORMAL, ALBEDO, MATERIAL, EMISSION, TRIANGLE, COVERAGE];

/// What the direct pass samples of the layer, in its G-buffer binding order.
pub const GBUFFER: [TargetDecl; 5] = [DEPTH, NORMAL, ALBEDO, MATERIAL, EMISSION];

/// The pixels where the see-through surfaces within world `bounds` may show through the
/// unjittered `view_proj` in a `width` × `height` image: their projected box, two pixels wider
/// on each side (the jitter of temporal anti-aliasing is below one), the whole image where a
/// corner lies behind the eye, none without see-through surfaces or off screen (zero extent).
/// The layer's passes draw and composite only there: clears and raster work on GPUs with few
/// raster units cost their area (an H200 took 1.05 ms for the layer over all of pica_pica's
/// 1600 × 900, for its three LEDs).
pub fn screen_area(
    bounds: Option<[glam::Vec3; 2]>,
    view_proj: glam::DMat4,
    width: u32,
    height: u32,
) -> vk::Rect2D {
    let none = vk::Rect2D::default();
    let Some([lo, hi]) = bounds else { return none };
    let whole = vk::Rect2D { offset: vk::Offset2D::default(), extent: vk::Extent2D { width, height } };
    let (mut min, mut max) = (glam::DVec2::splat(f64::INFINITY), glam::DVec2::splat(f64::NEG_INFINITY));
    for k in 0..8 {
        let pick = |axis: usize, l: f32, h: f32| f64::from(if k >> axis & 1 == 0 { l } else { h });
        let p = glam::DVec4::new(pick(0, lo.x, hi.x), pick(1, lo.y, hi.y), pick(2, lo.z, hi.z), 1.0);
        let clip = view_proj * p;
        if !(clip.w > 1e-9 * clip.truncate().length().max(1.0)) {
            return whole;
        }
        let ndc = glam::DVec2::new(clip.x, clip.y) / clip.w;
        // Image y runs down (the raster passes' viewport flips clip-space y).
        let at = glam::DVec2::new((ndc.x + 1.0) * 0.5 * width as f64, (1.0 - ndc.y) * 0.5 * height as f64);
        min = min.min(at);
        max = max.max(at);
    }
    let size = glam::DVec2::new(width as f64, height as f64);
    let (min, max) = (
        (min - 2.0).floor().clamp(glam::DVec2::ZERO, size),
        (max + 2.0).ceil().clamp(glam::DVec2::ZERO, size),
    );
    if !(max.x > min.x && max.y > min.y) {
        return none;
    }
    vk::Rect2D {
        offset: vk::Offset2D { x: min.x as i32, y: min.y as i32 },
        extent: vk::Extent2D { width: (max.x - min.x) as u32, height: (max.y - min.y) as u32 },
    }
}

/// The raster pass of the layer: the see-through surfaces drawn twice, once summing what each
/// lets through, once for the nearest's attributes.
#[derive(Debug)]
pub struct SeeThroughRaster {
    nearest: GraphicsPipeline,
    summed: GraphicsPipeline,
    draws: SceneDraws,
}

impl SeeThroughRaster {
    /// Builds the pipelines.
    pub fn new(gpu: &Gpu) -> PlayResult<SeeThroughRaster> {
        let draws = SceneDraws::see_through(gpu)?;
        let build = |fragment: &[u8], colors: &[vk::Format], landing| {
            draws.pipeline(gpu, fragment, colors, DEPTH.format, false, landing)
        };
        let nearest =
            build(spirv::shader!("gbuffer/see_through.frag"), &COLORS.map(|c| c.format), Landing::Nearest)?;
        let summed = draws.pipeline(
            gpu,
            spirv::shader!("gbuffer/see_through_absorbed.frag"),
            &[ABSORBED.format],
            vk::Format::UNDEFINED,
            false,
            Landing::Summed,
        )?;
        Ok(SeeThroughRaster { nearest, summed, draws })
    }
}

impl Pass for SeeThroughRaster {
    fn name(&self) -> &'static str {
        "see-through layer"
    }

    fn targets(&self, width: u32, height: u32) -> Vec<(TargetDecl, ImageDesc)> {
        COLORS.iter().chain([&ABSORBED, &DEPTH]).map(|t| (*t, t.sized(width, height, 1))).collect()
    }

    fn binds(&self) -> Vec<TargetDecl> {
        vec![OPAQUE_DEPTH]
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        self.draws.bind(gpu, shared)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let mut io: Vec<(TargetDecl, Access)> =
            COLORS.iter().chain([&ABSORBED]).map(|t| (*t, Access::Write(Use::COLOR))).collect();
        io.push((DEPTH, Access::Write(Use::DEPTH)));
        io.push((OPAQUE_DEPTH, Access::Read(Use::SAMPLED)));
        ctx.images.access(ctx.rec, &io);
        // Confined to the area the surfaces may cover (a pixel where none do: a render area
        // must not be empty, and the composition reads nothing outside the area). The sum is
        // cleared to zero; the nearest surface's targets need no clear, the composition reads
        // them only where the depth (cleared) says a surface was drawn.
        let area = ctx.see_through_area;
        let area = if area.extent.width == 0 {
            vk::Rect2D { offset: vk::Offset2D::default(), extent: vk::Extent2D { width: 1, height: 1 } }
        } else {
            area
        };
        ctx.rec.begin_rendering_in(&[ctx.images.get(&ABSORBED)], None, true, Some(area));
        if ctx.see_through_area.extent.width != 0 {
            self.draws.draw(ctx.rec, ctx.scene, |m| see_through(m).then_some(&self.summed));
        }
        ctx.rec.end_rendering();
        let colors: Vec<_> = COLORS.iter().map(|t| ctx.images.get(t)).collect();
        ctx.rec.begin_rendering_in(&colors, Some(ctx.images.get(&DEPTH)), false, Some(area));
        if ctx.see_through_area.extent.width != 0 {
            self.draws.draw(ctx.rec, ctx.scene, |m| see_through(m).then_some(&self.nearest));
        }
        ctx.rec.end_rendering();
    }
}

/// The layer's targets the composition samples, in binding order from 1.
const SAMPLED: [TargetDecl; 3] = [DEPTH, COVERAGE, ABSORBED];

/// The composition of the layer over the frame's radiance.
#[derive(Debug)]
pub struct SeeThroughComposite(Kernel);

impl SeeThroughComposite {
    /// Builds the pipeline.
    pub fn new(gpu: &Gpu) -> PlayResult<SeeThroughComposite> {
        use BindingKind::*;
        let mut bindings = vec![Binding::one(Uniform)];
        bindings.extend([Binding::one(Sampled); SAMPLED.len()]);
        bindings.extend([Binding::one(StorageImage); 2]);
        Ok(SeeThroughComposite(Kernel::new(gpu, &bindings, spirv::shader!("lighting/see_through.comp"), 16)?))
    }
}

impl Pass for SeeThroughComposite {
    fn name(&self) -> &'static str {
        "see-through composite"
    }

    fn binds(&self) -> Vec<TargetDecl> {
        let mut t = SAMPLED.to_vec();
        t.extend([RADIANCE, super::direct::RADIANCE]);
        t
    }

    fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let near = shared.scene.nearest_clamp;
        let img = |t: &TargetDecl| shared.images.get(t).view;
        let mut writes = vec![Write::Buffer(0, shared.frame_ubo)];
        for (i, t) in SAMPLED.iter().enumerate() {
            writes.push(Write::Sampled(1 + i as u32, vec![(img(t), near)]));
        }
        writes.push(Write::StorageImage(4, img(&RADIANCE)));
        writes.push(Write::StorageImage(5, img(&super::direct::RADIANCE)));
        self.0.write(gpu, &writes)
    }

    fn record(&mut self, ctx: &mut FrameCtx) {
        let mut io = super::gbuffer::sampled(&SAMPLED);
        io.push((RADIANCE, Access::Read(Use::STORAGE)));
        io.push((super::direct::RADIANCE, Access::ReadWrite(Use::STORAGE)));
        ctx.images.access(ctx.rec, &io);
        // The area as (x0, y0, x1, y1): nothing outside it changes.
        let a = ctx.see_through_area;
        let (x0, y0) = (a.offset.x.max(0) as u32, a.offset.y.max(0) as u32);
        let area = [x0, y0, x0 + a.extent.width, y0 + a.extent.height];
        self.0.dispatch(ctx.rec, bytemuck::cast_slice(&area), a.extent.width, a.extent.height);
    }
}
