//! Textures on the GPU: each texture's image with its full mip chain, its view and sampler,
//! uploaded as stored (RGBA8 or BC blocks), whole or streamed coarse levels first
//! ([`TextureUpload::CoarseFirst`]).

use kiln_format::manifest::{ColorSpace, Wrap};
use kiln_format::scene::SceneView;
use kiln_format::sections::{PixelFormat, Swizzle};

use super::upload::Uploader;
use super::{GpuScene, bad, sampled_desc};
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Gpu, Image, Sampler, SamplerKey, View, vk};

/// The largest side, in texels, of the finest level a streamed texture uploads before the first
/// frame: its levels from the first this small down to 1×1 come first. 256 keeps that part a
/// small fraction of the bytes (1/64 of a 2048² texture's chain, PICA PICA's size: 1.6 %),
/// while a level of 256 texels is sharp wherever the texture spans up to 256 pixels on screen,
/// the common case in a first frame over a scene with many textures.
pub const COARSE_SIDE: u32 = 256;

/// How textures reach the GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TextureUpload {
    /// Every level before the first frame.
    #[default]
    Whole,
    /// Each texture's levels from the first at most [`COARSE_SIDE`] texels on a side before the
    /// first frame, the finer ones after it ([`GpuScene::load_rest`]).
    CoarseFirst,
}

/// The first level of a `width` × `height` texture with `mips` levels that a streamed upload
/// sends before the first frame: the first whose larger side is at most [`COARSE_SIDE`] (the
/// last level when none is: a chain cut short), 0 for a texture already that small.
pub fn first_coarse_level(width: u32, height: u32, mips: u32) -> u32 {
    let last = mips.max(1) - 1;
    (0..=last).find(|&l| (width >> l).max(height >> l).max(1) <= COARSE_SIDE).unwrap_or(last)
}

/// A texture whose finer levels are still to come: the raster passes sample it through `view`
/// (its handle is in [`GpuScene::texture_views`]; held here to be released when dropped), which
/// starts at `first`, the finest level uploaded.
#[derive(Debug)]
pub(super) struct CoarseTexture {
    pub(super) texture: usize,
    first: u32,
    _view: View,
}

fn wrap_mode(w: Wrap) -> vk::SamplerAddressMode {
    match w {
        Wrap::Repeat => vk::SamplerAddressMode::REPEAT,
        Wrap::MirroredRepeat => vk::SamplerAddressMode::MIRRORED_REPEAT,
        Wrap::ClampToEdge => vk::SamplerAddressMode::CLAMP_TO_EDGE,
    }
}

impl GpuScene {
    /// Creates texture `i` with its full chain and uploads its levels: all of them, or with
    /// `coarse_first` those from [`first_coarse_level`] on; returns the finer levels left for
    /// [`GpuScene::refine_texture`] (finest, coarsest), if any.
    pub(super) fn upload_texture(
        &mut self,
        gpu: &Gpu,
        view: &SceneView,
        i: usize,
        up: &mut Uploader,
        coarse_first: bool,
    ) -> PlayResult<Option<[u32; 2]>> {
        let info = &view.manifest.textures[i];
        let data = view.texture(i).map_err(bad)?;
        let srgb = info.color_space == ColorSpace::Srgb;
        // The file's colour space and format were checked together (BC4 and BC5 are never sRGB).
        let format = match (data.format, srgb) {
            (PixelFormat::Rgba8, true) => vk::Format::R8G8B8A8_SRGB,
            (PixelFormat::Rgba8, false) => vk::Format::R8G8B8A8_UNORM,
            (PixelFormat::Bc7, true) => vk::Format::BC7_SRGB_BLOCK,
            (PixelFormat::Bc7, false) => vk::Format::BC7_UNORM_BLOCK,
            (PixelFormat::Bc5, _) => vk::Format::BC5_UNORM_BLOCK,
            (PixelFormat::Bc4, _) => vk::Format::BC4_UNORM_BLOCK,
        };
        if data.format.is_block_compressed() && !gpu.texture_compression_bc {
            return Err(PlayError::new(
                Exit::Unsupported,
                format!(
                    "texture {i} ('{}') is {}-compressed and {} cannot sample BC textures (no \
                     textureCompressionBC); recompile the scene with kiln compile --texture-format rgba8",
                    info.name,
                    data.format.name().to_uppercase(),
                    gpu.name
                ),
            ));
        }
        let swizzle = |s: Swizzle| match s {
            Swizzle::R => vk::ComponentSwizzle::R,
            Swizzle::G => vk::ComponentSwizzle::G,
            Swizzle::B => vk::ComponentSwizzle::B,
            Swizzle::A => vk::ComponentSwizzle::A,
            Swizzle::Zero => vk::ComponentSwizzle::ZERO,
            Swizzle::One => vk::ComponentSwizzle::ONE,
        };
        let mut desc = sampled_desc(format, info.width, info.height, info.mip_levels, 1, false);
        desc.components = vk::ComponentMapping {
            r: swizzle(data.swizzle[0]),
            g: swizzle(data.swizzle[1]),
            b: swizzle(data.swizzle[2]),
            a: swizzle(data.swizzle[3]),
        };
        let image = Image::new(gpu, &info.name, desc)?;
        let first =
            if coarse_first { first_coarse_level(info.width, info.height, info.mip_levels) } else { 0 };
        let slices = data.level_slices(info.width, info.height, info.mip_levels);
        let levels = texture_levels(info.width, info.height, &slices);
        let resident = &levels[(first as usize).min(levels.len())..];
        // Uploaded as stored: blocks go to the GPU as they are in the file.
        let uploaded =
            up.image_blocks(&image, data.format.block_dim(), data.format.block_bytes() as u64, resident);
        // Pushed first, so that the scene releases it on any error below. Textures arrive in
        // index order (file order), so position == texture number.
        debug_assert_eq!(self.textures.len(), i);
        self.texture_views.push(image.view);
        self.textures.push(image);
        uploaded?;
        self.coarse_texture_bytes += resident.iter().map(|l| l.4.len() as u64).sum::<u64>();
        if first > 0 {
            let coarse = self.textures[i].view_from_mip(gpu, first)?;
            self.texture_views[i] = coarse.raw;
            self.coarse.push(CoarseTexture { texture: i, first, _view: coarse });
        }
        let key = SamplerKey {
            linear: info.mag_linear,
            mipmaps: info.mip_levels > 1,
            wrap_u: wrap_mode(info.wrap_u),
            wrap_v: wrap_mode(info.wrap_v),
        };
        let raw = match self.samplers.get(&key) {
            Some(s) => s.raw,
            None => {
                let s = Sampler::new(gpu, key)?;
                let raw = s.raw;
                self.samplers.insert(key, s);
                raw
            }
        };
        self.texture_samplers.push(raw);
        Ok((first > 0).then(|| [0, first - 1]))
    }

    /// Uploads the finer levels that [`GpuScene::upload_texture`] left out of texture `i`,
    /// coarse to fine (nothing when it uploaded them all). Only those levels change layout:
    /// the coarse ones stay as they are, possibly sampled by a frame in flight.
    pub(super) fn refine_texture(&mut self, view: &SceneView, i: usize, up: &mut Uploader) -> PlayResult {
        let Some(first) = self.coarse.iter().find(|c| c.texture == i).map(|c| c.first) else {
            return Ok(());
        };
        let info = &view.manifest.textures[i];
        let data = view.texture(i).map_err(bad)?;
        let slices = data.level_slices(info.width, info.height, info.mip_levels);
        let levels = texture_levels(info.width, info.height, &slices);
        let fine: Vec<_> = levels[..(first as usize).min(levels.len())].iter().rev().copied().collect();
        up.image_blocks(&self.textures[i], data.format.block_dim(), data.format.block_bytes() as u64, &fine)?;
        self.fine_texture_bytes += fine.iter().map(|l| l.4.len() as u64).sum::<u64>();
        Ok(())
    }
}

/// A texture's levels as the uploader takes them, finest first: (mip, layer 0, width, height,
/// bytes as stored).
fn texture_levels<'a>(width: u32, height: u32, slices: &[&'a [u8]]) -> Vec<(u32, u32, u32, u32, &'a [u8])> {
    slices
        .iter()
        .enumerate()
        .map(|(mip, bytes)| {
            let mip = mip as u32;
            (mip, 0, (width >> mip).max(1), (height >> mip).max(1), *bytes)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_coarse_level_is_the_first_at_most_coarse_side_texels() {
        assert_eq!(first_coarse_level(2048, 2048, 12), 3);
        assert_eq!(first_coarse_level(2048, 512, 12), 3);
        assert_eq!(first_coarse_level(257, 3, 9), 1);
        assert_eq!(first_coarse_level(256, 256, 9), 0);
        assert_eq!(first_coarse_level(37, 29, 6), 0);
        // A chain cut short: its last level is the coarsest there is.
        assert_eq!(first_coarse_level(2048, 2048, 2), 1);
        assert_eq!(first_coarse_level(2048, 2048, 1), 0);
    }
}
