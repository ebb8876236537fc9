//! Window surface and swapchain: one frame in flight, an acquire semaphore reused each frame
//! (the previous frame's fence guards it) and a present semaphore per swapchain image.

use ash::vk;
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};

use super::{Gpu, Semaphore};
use crate::error::{Exit, PlayError, PlayResult, vk as vk_err};

/// Instance extensions a surface for `display` needs.
pub fn surface_extensions(display: RawDisplayHandle) -> PlayResult<Vec<*const std::ffi::c_char>> {
    ash_window::enumerate_required_extensions(display).map(|e| e.to_vec()).map_err(|e| {
        PlayError::new(Exit::Unsupported, format!("this display server has no Vulkan surface support: {e}"))
    })
}

/// A surface and its swapchain. Dropping it releases swapchain, surface and semaphores: the GPU
/// must be idle, and the window must still be open.
pub struct Swapchain {
    surface_loader: ash::khr::surface::Instance,
    surface: vk::SurfaceKHR,
    loader: ash::khr::swapchain::Device,
    raw: vk::SwapchainKHR,
    /// Swapchain images.
    pub images: Vec<vk::Image>,
    /// Their size.
    pub extent: vk::Extent2D,
    /// Signalled when the acquired image may be written.
    pub acquired: Semaphore,
    /// Per image: signalled when its frame is done, waited on by present.
    pub rendered: Vec<Semaphore>,
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        // SAFETY: made on this device and instance (a null swapchain is ignored); the owner
        // waited for the GPU. The semaphores, and the `Owner` they hold (device and instance),
        // go after this body.
        unsafe {
            self.loader.destroy_swapchain(self.raw, None);
            self.surface_loader.destroy_surface(self.surface, None);
        }
    }
}

impl std::fmt::Debug for Swapchain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Swapchain").field("extent", &self.extent).field("images", &self.images.len()).finish()
    }
}

impl Swapchain {
    /// A surface for the window and a swapchain of `width` × `height`.
    pub fn new(
        gpu: &Gpu,
        display: RawDisplayHandle,
        window: RawWindowHandle,
        width: u32,
        height: u32,
    ) -> PlayResult<Swapchain> {
        // SAFETY: the handles come from a live winit window that outlives the swapchain (the
        // window front end drops the swapchain first).
        let surface = unsafe { ash_window::create_surface(&gpu.entry, &gpu.instance, display, window, None) }
            .map_err(|e| vk_err("creating a window surface", e))?;
        let surface_loader = ash::khr::surface::Instance::new(&gpu.entry, &gpu.instance);
        let acquired = match gpu.binary_semaphore() {
            Ok(a) => a,
            Err(e) => {
                unsafe { surface_loader.destroy_surface(surface, None) };
                return Err(e);
            }
        };
        // Released on any error below.
        let mut s = Swapchain {
            surface_loader,
            surface,
            loader: ash::khr::swapchain::Device::new(&gpu.instance, &gpu.device),
            raw: vk::SwapchainKHR::null(),
            images: Vec::new(),
            extent: vk::Extent2D::default(),
            acquired,
            rendered: Vec::new(),
        };
        let supported = unsafe {
            s.surface_loader.get_physical_device_surface_support(gpu.physical, gpu.family, s.surface)
        }
        .unwrap_or(false);
        if !supported {
            return Err(PlayError::new(
                Exit::Unsupported,
                format!("{} cannot present to this window from its graphics queue", gpu.name),
            ));
        }
        s.recreate(gpu, width, height)?;
        Ok(s)
    }

    /// Rebuilds the swapchain for a new size (the GPU must be idle).
    pub fn recreate(&mut self, gpu: &Gpu, width: u32, height: u32) -> PlayResult {
        let caps = unsafe {
            self.surface_loader.get_physical_device_surface_capabilities(gpu.physical, self.surface)
        }
        .map_err(|e| vk_err("querying the surface", e))?;
        let formats =
            unsafe { self.surface_loader.get_physical_device_surface_formats(gpu.physical, self.surface) }
                .map_err(|e| vk_err("querying surface formats", e))?;
        // The display image already holds sRGB-encoded values: a UNORM swapchain takes them as
        // they are (an sRGB one would encode them twice).
        let format = formats
            .iter()
            .find(|f| f.format == vk::Format::B8G8R8A8_UNORM || f.format == vk::Format::R8G8B8A8_UNORM)
            .or(formats.first())
            .copied()
            .ok_or_else(|| PlayError::new(Exit::Unsupported, "the surface offers no formats"))?;
        if !caps.supported_usage_flags.contains(vk::ImageUsageFlags::TRANSFER_DST) {
            return Err(PlayError::new(
                Exit::Unsupported,
                "the surface's images cannot be blitted to (no TRANSFER_DST usage)",
            ));
        }
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let old = self.raw;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::COLOR_ATTACHMENT)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(vk::PresentModeKHR::FIFO)
            .clipped(true)
            .old_swapchain(old);
        self.raw = unsafe { self.loader.create_swapchain(&info, None) }
            .map_err(|e| vk_err("creating the swapchain", e))?;
        if old != vk::SwapchainKHR::null() {
            unsafe { self.loader.destroy_swapchain(old, None) };
        }
        self.images = unsafe { self.loader.get_swapchain_images(self.raw) }
            .map_err(|e| vk_err("listing swapchain images", e))?;
        self.extent = extent;
        self.rendered.clear();
        for _ in 0..self.images.len() {
            self.rendered.push(gpu.binary_semaphore()?);
        }
        Ok(())
    }

    /// Acquires the next image; `None` when the swapchain must be recreated first.
    pub fn acquire(&self) -> PlayResult<Option<u32>> {
        let acquired = self.acquired.raw;
        match unsafe { self.loader.acquire_next_image(self.raw, u64::MAX, acquired, vk::Fence::null()) } {
            Ok((i, _)) => Ok(Some(i)),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(None),
            Err(e) => Err(vk_err("acquiring a swapchain image", e)),
        }
    }

    /// Presents image `index`; returns false when the swapchain should be recreated.
    pub fn present(&self, gpu: &Gpu, index: u32) -> PlayResult<bool> {
        let waits = [self.rendered[index as usize].raw];
        let swapchains = [self.raw];
        let indices = [index];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        match unsafe { self.loader.queue_present(gpu.queue, &info) } {
            Ok(false) => Ok(true),
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(false),
            Err(e) => Err(vk_err("presenting", e)),
        }
    }
}
