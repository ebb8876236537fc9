//! Placeholder images for descriptors that must be valid but are never read.

use crate::gpu::vk;

use crate::error::PlayResult;
use crate::gpu::{Gpu, Image};
use crate::scene::sampled_desc;
use crate::scene::upload::Uploader;

/// Placeholder images for descriptors that must be valid but are never read (released when
/// dropped, after every frame that bound them).
#[derive(Debug)]
pub struct Dummies {
    /// 1 × 1 white RGBA8 (absent textures, absent BRDF table).
    pub white: Image,
    /// 1 × 1 R32F at f32::MAX (unused 2D shadow slots).
    pub shadow_2d: Image,
    /// 1 × 1 × 6 R32F cube at f32::MAX (unused cube slots).
    pub shadow_cube: Image,
    /// 1 × 1, one layer, RGBA8 2D array (absent probe atlases).
    pub array: Image,
}

impl Dummies {
    /// Creates and uploads the placeholders (all made before any upload is recorded: one
    /// that fails to be made leaves no upload naming the others).
    pub fn new(gpu: &Gpu, up: &mut Uploader) -> PlayResult<Dummies> {
        let white = Image::new(gpu, "white", sampled_desc(vk::Format::R8G8B8A8_UNORM, 1, 1, 1, 1, false))?;
        let shadow_2d =
            Image::new(gpu, "no shadow 2d", sampled_desc(vk::Format::R32_SFLOAT, 1, 1, 1, 1, false))?;
        let shadow_cube =
            Image::new(gpu, "no shadow cube", sampled_desc(vk::Format::R32_SFLOAT, 1, 1, 1, 6, true))?;
        let mut array_desc = sampled_desc(vk::Format::R8G8B8A8_UNORM, 1, 1, 1, 1, false);
        array_desc.array = true;
        let array = Image::new(gpu, "no array", array_desc)?;
        up.image(&white, 4, &[(0, 0, 1, 1, &[255u8; 4])])?;
        let far = f32::MAX.to_le_bytes();
        up.image(&shadow_2d, 4, &[(0, 0, 1, 1, &far)])?;
        let faces: Vec<(u32, u32, u32, u32, &[u8])> = (0..6).map(|f| (0, f, 1, 1, &far[..])).collect();
        up.image(&shadow_cube, 4, &faces)?;
        up.image(&array, 4, &[(0, 0, 1, 1, &[0u8; 4])])?;
        Ok(Dummies { white, shadow_2d, shadow_cube, array })
    }
}
