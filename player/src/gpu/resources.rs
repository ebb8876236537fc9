//! Buffers, images and samplers, with their memory from `gpu-allocator`. Each owns its handle
//! and memory and releases them when dropped (no submitted work may still use it then).

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};

use super::{Gpu, Owner};
use crate::error::{Exit, PlayError, PlayResult, vk as vk_err};

fn alloc_err(what: &str, e: gpu_allocator::AllocationError) -> PlayError {
    PlayError::new(Exit::Gpu, format!("allocating memory for {what} failed: {e}"))
}

/// A buffer and its memory, released when dropped.
#[derive(Debug)]
pub struct Buffer {
    /// Handle.
    pub raw: vk::Buffer,
    /// Size in bytes.
    pub size: u64,
    allocation: Option<Allocation>,
    owner: Arc<Owner>,
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: made on this device; its owner guarantees no submitted work uses it any more.
        unsafe { self.owner.device.destroy_buffer(self.raw, None) };
        if let Some(a) = self.allocation.take() {
            let _ = self.owner.allocator().free(a);
        }
    }
}

impl Buffer {
    /// A buffer of `size` bytes (at least 4) for `usage`, in `location`, used by the graphics
    /// queue only.
    pub fn new(
        gpu: &Gpu,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> PlayResult<Buffer> {
        Self::create(gpu, name, size, usage, location, &[])
    }

    /// A device-local buffer filled by uploads (shared with the transfer queue when there is one).
    pub fn uploaded(gpu: &Gpu, name: &str, size: u64, usage: vk::BufferUsageFlags) -> PlayResult<Buffer> {
        let families = gpu.queue_families();
        Self::create(
            gpu,
            name,
            size,
            usage | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
            &families,
        )
    }

    fn create(
        gpu: &Gpu,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
        families: &[u32],
    ) -> PlayResult<Buffer> {
        let size = size.max(4).next_multiple_of(4);
        let mut info =
            vk::BufferCreateInfo::default().size(size).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        if families.len() > 1 {
            info = info.sharing_mode(vk::SharingMode::CONCURRENT).queue_family_indices(families);
        }
        let raw =
            unsafe { gpu.device.create_buffer(&info, None) }.map_err(|e| vk_err("creating a buffer", e))?;
        // Released on any error below.
        let mut buffer = Buffer { raw, size, allocation: None, owner: gpu.owner() };
        let requirements = unsafe { gpu.device.get_buffer_memory_requirements(raw) };
        let allocation = gpu
            .allocator()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| alloc_err(name, e))?;
        let bound = unsafe { gpu.device.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) };
        buffer.allocation = Some(allocation);
        bound.map_err(|e| vk_err("binding buffer memory", e))?;
        Ok(buffer)
    }

    /// The buffer's device address (it must have been created with SHADER_DEVICE_ADDRESS usage).
    pub fn address(&self, gpu: &Gpu) -> u64 {
        let info = vk::BufferDeviceAddressInfo::default().buffer(self.raw);
        unsafe { gpu.device.get_buffer_device_address(&info) }
    }

    /// The mapped bytes of a host-visible buffer.
    pub fn mapped(&mut self) -> Option<&mut [u8]> {
        self.allocation.as_mut().and_then(|a| a.mapped_slice_mut())
    }

    /// Writes `data` at the start of a host-visible buffer.
    pub fn write(&mut self, data: &[u8]) -> PlayResult {
        let dst = self.mapped().ok_or_else(|| PlayError::new(Exit::Gpu, "buffer is not host-visible"))?;
        dst[..data.len()].copy_from_slice(data);
        Ok(())
    }
}

/// What an image is.
#[derive(Debug, Clone, Copy)]
pub struct ImageDesc {
    /// Format.
    pub format: vk::Format,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Mip levels.
    pub mips: u32,
    /// Array layers (6 for cube maps).
    pub layers: u32,
    /// Cube compatible.
    pub cube: bool,
    /// Viewed as a 2D array (even with one layer); otherwise 2D or cube.
    pub array: bool,
    /// Usage.
    pub usage: vk::ImageUsageFlags,
    /// Filled by uploads: shared with the transfer queue when there is one.
    pub uploaded: bool,
    /// Channel swizzle of the default view (identity for all but block-compressed textures
    /// with fewer than four channels).
    pub components: vk::ComponentMapping,
}

/// An image, its default view and memory, released when dropped (extra [`View`]s of it
/// should go first).
#[derive(Debug)]
pub struct Image {
    /// Handle.
    pub raw: vk::Image,
    /// View over all mips and layers (cube view for cube maps).
    pub view: vk::ImageView,
    /// Description.
    pub desc: ImageDesc,
    allocation: Option<Allocation>,
    owner: Arc<Owner>,
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: made on this device (a null view is ignored); its owner guarantees no
        // submitted work uses it any more.
        unsafe {
            self.owner.device.destroy_image_view(self.view, None);
            self.owner.device.destroy_image(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            let _ = self.owner.allocator().free(a);
        }
    }
}

impl Image {
    /// A device-local image.
    pub fn new(gpu: &Gpu, name: &str, desc: ImageDesc) -> PlayResult<Image> {
        let families = gpu.queue_families();
        let mut info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D { width: desc.width.max(1), height: desc.height.max(1), depth: 1 })
            .mip_levels(desc.mips.max(1))
            .array_layers(desc.layers.max(1))
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .flags(if desc.cube {
                vk::ImageCreateFlags::CUBE_COMPATIBLE
            } else {
                vk::ImageCreateFlags::empty()
            })
            .initial_layout(vk::ImageLayout::UNDEFINED);
        if desc.uploaded && families.len() > 1 {
            info = info.sharing_mode(vk::SharingMode::CONCURRENT).queue_family_indices(&families);
        }
        let raw =
            unsafe { gpu.device.create_image(&info, None) }.map_err(|e| vk_err("creating an image", e))?;
        // Released on any error below.
        let mut image =
            Image { raw, view: vk::ImageView::null(), desc, allocation: None, owner: gpu.owner() };
        let requirements = unsafe { gpu.device.get_image_memory_requirements(raw) };
        let allocation = gpu
            .allocator()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| alloc_err(name, e))?;
        let bound = unsafe { gpu.device.bind_image_memory(raw, allocation.memory(), allocation.offset()) };
        image.allocation = Some(allocation);
        bound.map_err(|e| vk_err("binding image memory", e))?;
        image.view = create_view(gpu, raw, &desc, 0)?;
        Ok(image)
    }

    /// A view of mips `base` to the last (every layer), for sampling while only those levels
    /// hold data: a sampler never reads a level outside its view.
    pub fn view_from_mip(&self, gpu: &Gpu, base: u32) -> PlayResult<View> {
        let raw = create_view(gpu, self.raw, &self.desc, base.min(self.desc.mips.max(1) - 1))?;
        Ok(View { raw, owner: gpu.owner() })
    }

    /// Range covering `count` mips from `base` and every layer.
    pub fn mips(&self, base: u32, count: u32) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange { base_mip_level: base, level_count: count, ..self.range() }
    }

    /// Range covering every mip and layer.
    pub fn range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: aspect_of(self.desc.format),
            base_mip_level: 0,
            level_count: self.desc.mips.max(1),
            base_array_layer: 0,
            layer_count: self.desc.layers.max(1),
        }
    }
}

/// A view of `desc`'s image `raw` over mips `base` to the last and every layer (cube view for
/// cube maps), with `desc`'s swizzle.
fn create_view(gpu: &Gpu, raw: vk::Image, desc: &ImageDesc, base: u32) -> PlayResult<vk::ImageView> {
    let mips = desc.mips.max(1);
    let view_info = vk::ImageViewCreateInfo::default()
        .image(raw)
        .view_type(if desc.cube {
            vk::ImageViewType::CUBE
        } else if desc.array {
            vk::ImageViewType::TYPE_2D_ARRAY
        } else {
            vk::ImageViewType::TYPE_2D
        })
        .format(desc.format)
        .components(desc.components)
        .subresource_range(vk::ImageSubresourceRange {
            aspect_mask: aspect_of(desc.format),
            base_mip_level: base,
            level_count: mips - base,
            base_array_layer: 0,
            layer_count: desc.layers.max(1),
        });
    unsafe { gpu.device.create_image_view(&view_info, None) }.map_err(|e| vk_err("creating an image view", e))
}

/// An extra view of an image (the image's own is [`Image::view`]), released when dropped; its
/// owner drops it before the image.
#[derive(Debug)]
pub struct View {
    /// Handle.
    pub raw: vk::ImageView,
    owner: Arc<Owner>,
}

impl Drop for View {
    fn drop(&mut self) {
        // SAFETY: made on this device; its owner guarantees no submitted work uses it any more.
        unsafe { self.owner.device.destroy_image_view(self.raw, None) };
    }
}

/// The aspect of a format.
pub fn aspect_of(format: vk::Format) -> vk::ImageAspectFlags {
    match format {
        vk::Format::D32_SFLOAT | vk::Format::D16_UNORM => vk::ImageAspectFlags::DEPTH,
        _ => vk::ImageAspectFlags::COLOR,
    }
}

/// How a sampler filters and wraps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SamplerKey {
    /// Linear magnification and minification (else nearest).
    pub linear: bool,
    /// Trilinear mip filtering.
    pub mipmaps: bool,
    /// Address mode along u.
    pub wrap_u: vk::SamplerAddressMode,
    /// Address mode along v.
    pub wrap_v: vk::SamplerAddressMode,
}

/// A sampler, released when dropped.
#[derive(Debug)]
pub struct Sampler {
    /// Handle.
    pub raw: vk::Sampler,
    owner: Arc<Owner>,
}

impl Drop for Sampler {
    fn drop(&mut self) {
        // SAFETY: made on this device; its owner guarantees no submitted work uses it any more.
        unsafe { self.owner.device.destroy_sampler(self.raw, None) };
    }
}

impl Sampler {
    /// A sampler for `key`.
    pub fn new(gpu: &Gpu, key: SamplerKey) -> PlayResult<Sampler> {
        let filter = if key.linear { vk::Filter::LINEAR } else { vk::Filter::NEAREST };
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(filter)
            .min_filter(filter)
            .mipmap_mode(if key.mipmaps {
                vk::SamplerMipmapMode::LINEAR
            } else {
                vk::SamplerMipmapMode::NEAREST
            })
            .address_mode_u(key.wrap_u)
            .address_mode_v(key.wrap_v)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(if key.mipmaps { vk::LOD_CLAMP_NONE } else { 0.0 });
        let raw =
            unsafe { gpu.device.create_sampler(&info, None) }.map_err(|e| vk_err("creating a sampler", e))?;
        Ok(Sampler { raw, owner: gpu.owner() })
    }
}
