//! The per-size images of a frame: the G-buffer, the linear radiance and the display image.

use ash::vk;

use crate::error::PlayResult;
use crate::gpu::{Gpu, Image, ImageDesc};

/// G-buffer formats, in attachment order (see `shaders/gbuffer/gbuffer.frag`).
pub const GBUFFER_FORMATS: [vk::Format; 4] = [
    vk::Format::R16G16_SNORM,
    vk::Format::R8G8B8A8_SRGB,
    vk::Format::R8G8B8A8_UNORM,
    vk::Format::R16G16B16A16_SFLOAT,
];
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
    /// Normal, albedo, material, emission.
    pub gbuffer: Vec<Image>,
    /// Depth (reversed Z).
    pub depth: Image,
    /// Linear scene radiance.
    pub radiance: Image,
    /// Tone-mapped result.
    pub display: Image,
}

fn desc(format: vk::Format, width: u32, height: u32, usage: vk::ImageUsageFlags) -> ImageDesc {
    ImageDesc { format, width, height, mips: 1, layers: 1, cube: false, usage, uploaded: false }
}

impl Targets {
    /// Targets of `width` × `height`.
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> PlayResult<Targets> {
        let attach = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let mut gbuffer = Vec::new();
        for (i, f) in GBUFFER_FORMATS.iter().enumerate() {
            gbuffer.push(Image::new(gpu, &format!("gbuffer {i}"), desc(*f, width, height, attach))?);
        }
        let depth = Image::new(
            gpu,
            "depth",
            desc(
                DEPTH_FORMAT,
                width,
                height,
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            ),
        )?;
        let storage = vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::TRANSFER_SRC;
        let radiance = Image::new(gpu, "radiance", desc(RADIANCE_FORMAT, width, height, storage))?;
        let display = Image::new(gpu, "display", desc(DISPLAY_FORMAT, width, height, storage))?;
        Ok(Targets { width, height, gbuffer, depth, radiance, display })
    }

    /// Releases the images.
    pub fn destroy(&mut self, gpu: &Gpu) {
        for i in &mut self.gbuffer {
            i.destroy(gpu);
        }
        self.depth.destroy(gpu);
        self.radiance.destroy(gpu);
        self.display.destroy(gpu);
    }
}
