//! The per-size images of a frame: the G-buffer, the linear radiance and the display image.

use ash::vk;

use crate::error::PlayResult;
use crate::gpu::{Gpu, Image, ImageDesc};

/// G-buffer formats, in attachment order (see `shaders/gbuffer/gbuffer.frag`).
pub const GBUFFER_FORMATS: [vk::Format; 5] = [
    vk::Format::R16G16_SNORM,
    vk::Format::R8G8B8A8_UNORM,
    vk::Format::R8G8B8A8_UNORM,
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::R32_UINT,
];
/// Index of the triangle target in [`GBUFFER_FORMATS`] (the visibility buffer).
pub const TRIANGLE_TARGET: usize = 4;
/// Depth format.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Linear radiance format (what `-o x.exr` writes).
pub const RADIANCE_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// Tone-mapped display format (sRGB-encoded values in a UNORM image).
pub const DISPLAY_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

/// The images one frame renders into.
#[derive(Debug)]
pub struct Targets {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Normal, albedo, material, emission, triangle.
    pub gbuffer: Vec<Image>,
    /// Depth (reversed Z).
    pub depth: Image,
    /// Linear scene radiance.
    pub radiance: Image,
    /// Tone-mapped result.
    pub display: Image,
    /// Ray-traced shadow visibility, one layer per light (1 × 1 when the pass is off).
    pub rt_shadows: Image,
    /// Ray-traced ambient openness (1 × 1 when off).
    pub rt_ao: Image,
    /// Ray-traced reflections, full or half size (1 × 1 when off).
    pub rt_reflections: Image,
    /// Between the reflection passes: radiance without the lights' shadowed terms.
    pub refl_partial: Image,
    /// Between the reflection passes: the hits' offset ray origins.
    pub refl_origin: Image,
    /// Between the reflection passes: each light's unshadowed term (one layer per light).
    pub refl_lights: Image,
    /// What the ray-traced images were made for.
    pub rt: RtShape,
    /// The ray-traced images hold nothing yet (their first use discards).
    pub rt_fresh: bool,
}

/// Sizes of the ray-traced passes' accumulation images.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RtShape {
    /// Lights with a ray-traced shadow layer (0: the pass is off).
    pub shadow_layers: u32,
    /// The AO pass is on.
    pub ao: bool,
    /// Pixels per reflection sample along each axis (0: the pass is off).
    pub reflection_step: u32,
    /// Lights whose reflection-hit shadow rays the separate shadow pass traces.
    pub reflection_lights: u32,
}

fn desc(format: vk::Format, width: u32, height: u32, usage: vk::ImageUsageFlags) -> ImageDesc {
    ImageDesc { format, width, height, mips: 1, layers: 1, cube: false, array: false, usage, uploaded: false }
}

impl Targets {
    /// Targets of `width` × `height`. On failure the images already made are released.
    pub fn new(gpu: &Gpu, width: u32, height: u32, rt: RtShape) -> PlayResult<Targets> {
        // Storage too: the visibility-buffer resolve writes the material targets in compute.
        let attach = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::STORAGE;
        let storage = vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::TRANSFER_SRC;
        let accumulation = vk::ImageUsageFlags::STORAGE;
        let on = |yes: bool, n: u32| if yes { n } else { 1 };
        let step = rt.reflection_step.max(1);
        let (rw, rh) = (
            on(rt.reflection_step > 0, width.div_ceil(step)),
            on(rt.reflection_step > 0, height.div_ceil(step)),
        );
        let array = |mut d: ImageDesc, layers: u32| {
            d.layers = layers.max(1);
            d.array = true;
            d
        };
        // In field order: the G-buffer, depth, radiance, display, then the ray-traced images.
        let mut wanted: Vec<(String, ImageDesc)> = GBUFFER_FORMATS
            .iter()
            .enumerate()
            .map(|(i, f)| (format!("gbuffer {i}"), desc(*f, width, height, attach)))
            .collect();
        let depth_usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let r32 = vk::Format::R32_SFLOAT;
        let rgba32 = vk::Format::R32G32B32A32_SFLOAT;
        let shadow_size = |n: u32| on(rt.shadow_layers > 0, n);
        wanted.extend([
            ("depth".into(), desc(DEPTH_FORMAT, width, height, depth_usage)),
            ("radiance".into(), desc(RADIANCE_FORMAT, width, height, storage)),
            ("display".into(), desc(DISPLAY_FORMAT, width, height, storage)),
            (
                "rt shadows".into(),
                array(desc(r32, shadow_size(width), shadow_size(height), accumulation), rt.shadow_layers),
            ),
            ("rt ao".into(), desc(r32, on(rt.ao, width), on(rt.ao, height), accumulation)),
            ("rt reflections".into(), desc(rgba32, rw, rh, accumulation)),
            ("reflection partial".into(), desc(rgba32, rw, rh, accumulation)),
            ("reflection origins".into(), desc(rgba32, rw, rh, accumulation)),
            (
                "reflection light terms".into(),
                array(desc(rgba32, rw, rh, accumulation), rt.reflection_lights),
            ),
        ]);
        let mut made = Vec::with_capacity(wanted.len());
        for (name, d) in wanted {
            match Image::new(gpu, &name, d) {
                Ok(image) => made.push(image),
                Err(e) => {
                    for mut image in made {
                        image.destroy(gpu);
                    }
                    return Err(e);
                }
            }
        }
        let mut it = made.into_iter();
        let mut next = || it.next().expect("one image per description");
        let gbuffer = (0..GBUFFER_FORMATS.len()).map(|_| next()).collect();
        Ok(Targets {
            width,
            height,
            gbuffer,
            depth: next(),
            radiance: next(),
            display: next(),
            rt_shadows: next(),
            rt_ao: next(),
            rt_reflections: next(),
            refl_partial: next(),
            refl_origin: next(),
            refl_lights: next(),
            rt,
            rt_fresh: true,
        })
    }

    /// Releases the images.
    pub fn destroy(&mut self, gpu: &Gpu) {
        for i in &mut self.gbuffer {
            i.destroy(gpu);
        }
        self.depth.destroy(gpu);
        self.radiance.destroy(gpu);
        self.display.destroy(gpu);
        self.rt_shadows.destroy(gpu);
        self.rt_ao.destroy(gpu);
        self.rt_reflections.destroy(gpu);
        self.refl_partial.destroy(gpu);
        self.refl_origin.destroy(gpu);
        self.refl_lights.destroy(gpu);
    }
}
