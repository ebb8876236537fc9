//! The only module that speaks raw Vulkan (`ash`). Everything above it — loading, passes, front
//! ends — uses the types and safe functions here.
//!
//! Vulkan 1.3 core with dynamic rendering, synchronization2, timeline semaphores and buffer device
//! address; memory through `gpu-allocator`; a pipeline cache kept on disk between runs.
//!
//! Every type here that owns a Vulkan object or an allocation releases it when dropped. Each
//! holds the device's [`Owner`] (shared with the [`Gpu`]), so the device, the allocator and the
//! instance go only after the last object made on them. Vulkan's own rule stays the owner's
//! to keep: no submitted work may still use an object when it is dropped. The front ends wait
//! for the GPU (or for the command pool that submitted the work) before they drop what it used,
//! and say so where they do.

mod commands;
mod pipelines;
pub mod process;
mod raytracing;
mod resources;
mod swapchain;

pub use commands::{CommandPool, ImageRows, Recorder, Semaphore, SemaphoreOp, TimestampPool, Use};
pub use pipelines::{
    Binding, BindingKind, ComputePipeline, GraphicsDesc, GraphicsPipeline, Landing, SetLayout, Write,
};
pub use raytracing::{AccelerationStructures, RayTracingPipeline, RayTracingShaders};
pub use resources::{Buffer, Image, ImageDesc, Sampler, SamplerKey, View};
pub use swapchain::{Swapchain, surface_extensions};

use std::ffi::{CStr, CString, c_void};
use std::mem::ManuallyDrop;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

pub use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use crate::error::{Exit, PlayError, PlayResult, vk as vk_err};

/// What the caller wants of the device.
#[derive(Debug, Clone, Default)]
pub struct GpuOptions {
    /// Enable the Khronos validation layer and count its errors.
    pub validate: bool,
    /// Pick the first device whose name contains this (case-insensitive).
    pub device: Option<String>,
    /// Instance extensions a window surface needs (empty when headless).
    pub surface_extensions: Vec<*const std::ffi::c_char>,
    /// Keep the pipeline cache in this file.
    pub pipeline_cache: Option<PathBuf>,
    /// Enable the driver's ray-tracing pipeline and acceleration structures when the device has
    /// them (the peer of the compute traversal in `--bench-rays`).
    pub ray_tracing_pipeline: bool,
    /// Caps one storage buffer below the device's `maxStorageBufferRange` (tests split a small
    /// scene's line space into several buffers as a large one is split on any device).
    pub max_storage_buffer: Option<u64>,
}

/// Counts of validation messages (errors are what tests require to be zero).
#[derive(Debug, Default)]
pub struct ValidationCounts {
    /// Error messages.
    pub errors: AtomicU32,
    /// Warning messages.
    pub warnings: AtomicU32,
}

/// A device as a benchmark record names it.
#[derive(Debug, Clone, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct DeviceIdentity {
    /// Device name.
    pub name: String,
    /// Driver name (e.g. "NVIDIA", "llvmpipe").
    pub driver_name: String,
    /// Driver's own description of its version.
    pub driver_info: String,
    /// Driver version, decoded.
    pub driver_version: String,
    /// The device UUID (hex), stable across runs on one GPU.
    pub uuid: String,
}

/// The Vulkan context: instance, device, queues, allocator.
pub struct Gpu {
    /// Loader entry points.
    pub entry: ash::Entry,
    /// Instance.
    pub instance: ash::Instance,
    /// Chosen physical device.
    pub physical: vk::PhysicalDevice,
    /// Its properties.
    pub properties: vk::PhysicalDeviceProperties,
    /// Its name.
    pub name: String,
    /// Logical device.
    pub device: ash::Device,
    /// Graphics + compute queue family.
    pub family: u32,
    /// The graphics + compute queue.
    pub queue: vk::Queue,
    /// A dedicated transfer queue (family, queue), when the device has one.
    pub transfer: Option<(u32, vk::Queue)>,
    /// Validation message counts (boxed: the messenger holds a pointer to it).
    /// Shared, so that messages sent while the device is destroyed (leaked objects) can still be
    /// counted by whoever holds a clone.
    pub validation: Arc<ValidationCounts>,
    /// Pipeline cache.
    pub pipeline_cache: vk::PipelineCache,
    cache_path: Option<PathBuf>,
    /// Whether VK_KHR_ray_tracing_pipeline and VK_KHR_acceleration_structure are enabled.
    pub ray_tracing_pipeline: bool,
    storage_cap: Option<u64>,
    /// The device samples BC-compressed images (`textureCompressionBC`, enabled).
    pub texture_compression_bc: bool,
    /// Device, allocator and instance, shared with every object made on them (dropped last).
    owner: Arc<Owner>,
}

/// The instance and its debug messenger, destroyed when dropped (after the device: an
/// [`Owner`] holds it).
struct Instance {
    instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// The counts the messenger writes (its user data), kept until the instance is gone.
    _validation: Arc<ValidationCounts>,
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: no device made on the instance is left (an `Owner` destroys its device before
        // its `Instance` field is dropped, and `Gpu::new` its own on every error).
        unsafe {
            if let Some((utils, messenger)) = &self.debug {
                utils.destroy_debug_utils_messenger(*messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// The logical device, its memory allocator and the instance: what each object made on the
/// device needs to release itself. The [`Gpu`] and every such object hold it (`Arc`); the last
/// one to go destroys the allocator, the device and the instance, in that order, so the device
/// always outlives what was made on it.
pub(crate) struct Owner {
    /// Logical device.
    pub(crate) device: ash::Device,
    allocator: ManuallyDrop<Mutex<Allocator>>,
    /// Dropped after the device (fields drop after `drop`'s body).
    _instance: Instance,
}

impl Owner {
    /// The memory allocator (locked while the guard lives).
    pub(crate) fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|p| p.into_inner())
    }
}

impl std::fmt::Debug for Owner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Owner").finish_non_exhaustive()
    }
}

impl Drop for Owner {
    fn drop(&mut self) {
        // SAFETY: every object made on the device held this `Owner` and is gone, its memory
        // returned to the allocator; the `Gpu` waited for the device to go idle when it was
        // dropped, and nothing was submitted after it.
        unsafe {
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_device(None);
        }
    }
}

/// Device extensions the ray-tracing-pipeline peer needs.
const RT_PIPELINE_EXTENSIONS: [&std::ffi::CStr; 3] = [
    ash::khr::acceleration_structure::NAME,
    ash::khr::ray_tracing_pipeline::NAME,
    ash::khr::deferred_host_operations::NAME,
];

impl std::fmt::Debug for Gpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gpu").field("name", &self.name).finish()
    }
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the loader passes valid callback data; `user` is the `ValidationCounts` box, which
    // outlives the messenger (the `Instance` that destroys the messenger holds it).
    let (counts, message) = unsafe {
        let counts = &*(user as *const ValidationCounts);
        let msg = if data.is_null() || (*data).p_message.is_null() {
            String::new()
        } else {
            CStr::from_ptr((*data).p_message).to_string_lossy().into_owned()
        };
        (counts, msg)
    };
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        counts.errors.fetch_add(1, Ordering::Relaxed);
        eprintln!("vulkan validation error: {message}");
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        counts.warnings.fetch_add(1, Ordering::Relaxed);
        eprintln!("vulkan validation warning: {message}");
    }
    vk::FALSE
}

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

fn unsupported(msg: impl Into<String>) -> PlayError {
    PlayError::new(Exit::Unsupported, msg)
}

/// The Vulkan loader, loaded once per process, with one bare instance kept alive beside it.
///
/// The loader loads the drivers (ICDs) when an instance is created and unloads them when the
/// last one is destroyed. NVIDIA's driver does not survive many such cycles in one process: on
/// the H100, kiln-bench's 28th session (one per configuration) failed to create its instance
/// with `ERROR_INCOMPATIBLE_DRIVER`. The kept instance holds the drivers loaded, so sessions
/// come and go without reloading them. It has no layers and no objects, and ends with the process.
fn loader() -> Result<ash::Entry, String> {
    static LOADED: std::sync::OnceLock<Result<ash::Entry, String>> = std::sync::OnceLock::new();
    LOADED
        .get_or_init(|| {
            // SAFETY: loading the system's Vulkan loader; its symbols are only called through ash.
            let entry = unsafe { ash::Entry::load() }.map_err(|e| e.to_string())?;
            let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_0);
            // SAFETY: `app` outlives the call. A failure here is left for the session's own
            // instance to report in full.
            let _kept = unsafe {
                entry.create_instance(&vk::InstanceCreateInfo::default().application_info(&app), None)
            };
            Ok(entry)
        })
        .clone()
}

impl Gpu {
    /// Creates instance and device, or says precisely why not.
    pub fn new(options: &GpuOptions) -> PlayResult<Gpu> {
        let entry = loader().map_err(|e| {
            unsupported(format!(
                "no Vulkan loader ({e}): install a Vulkan driver, or Mesa's CPU driver lavapipe (Debian: libvulkan1 mesa-vulkan-drivers)"
            ))
        })?;
        let version =
            unsafe { entry.try_enumerate_instance_version() }.ok().flatten().unwrap_or(vk::API_VERSION_1_0);
        if version < vk::API_VERSION_1_3 {
            return Err(unsupported(format!(
                "the Vulkan loader supports {}.{}, kiln-play needs 1.3",
                vk::api_version_major(version),
                vk::api_version_minor(version)
            )));
        }
        let mut layers = Vec::new();
        let mut extensions: Vec<*const std::ffi::c_char> = options.surface_extensions.clone();
        if options.validate {
            let available = unsafe { entry.enumerate_instance_layer_properties() }
                .map_err(|e| vk_err("listing layers", e))?;
            let found = available.iter().any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER));
            if !found {
                return Err(unsupported(
                    "--validate: the Khronos validation layer is not installed (Debian: vulkan-validationlayers)",
                ));
            }
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        let app_name = CString::new("kiln-play").unwrap_or_default();
        let app = vk::ApplicationInfo::default().application_name(&app_name).api_version(vk::API_VERSION_1_3);
        let validation = Arc::new(ValidationCounts::default());
        let mut messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                    | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(debug_callback))
            .user_data(Arc::as_ptr(&validation) as *mut c_void);
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if options.validate {
            info = info.push_next(&mut messenger_info);
        }
        // SAFETY: all pointers in `info` live until the call returns.
        let instance = unsafe { entry.create_instance(&info, None) }.map_err(|e| match e {
            vk::Result::ERROR_INCOMPATIBLE_DRIVER => unsupported(
                "no Vulkan driver found: install your GPU's driver, or Mesa's CPU driver lavapipe (Debian: mesa-vulkan-drivers)",
            ),
            e => vk_err("creating the Vulkan instance", e),
        })?;
        // Destroyed when dropped: on an error below, or with the last holder of the device.
        let mut owned = Instance { instance: instance.clone(), debug: None, _validation: validation.clone() };
        if options.validate {
            let utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let messenger = unsafe { utils.create_debug_utils_messenger(&messenger_info, None) }
                .map_err(|e| vk_err("creating the debug messenger", e))?;
            owned.debug = Some((utils, messenger));
        }
        let (physical, family, transfer_family) = pick_device(&instance, options)?;
        let properties = unsafe { instance.get_physical_device_properties(physical) };
        let name =
            properties.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();

        let priorities = [1.0f32];
        let mut queue_infos = vec![
            vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities),
        ];
        if let Some(t) = transfer_family {
            queue_infos.push(
                vk::DeviceQueueCreateInfo::default().queue_family_index(t).queue_priorities(&priorities),
            );
        }
        let mut device_extensions = Vec::new();
        if !options.surface_extensions.is_empty() {
            device_extensions.push(ash::khr::swapchain::NAME.as_ptr());
        }
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
            .timeline_semaphore(true)
            .buffer_device_address(true)
            .scalar_block_layout(true);
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .synchronization2(true)
            .maintenance4(true);
        let available: Vec<std::ffi::CString> =
            unsafe { instance.enumerate_device_extension_properties(physical) }
                .unwrap_or_default()
                .iter()
                .filter_map(|e| e.extension_name_as_c_str().ok().map(|c| c.to_owned()))
                .collect();
        let mut accel = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
        let mut rtp = vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default();
        let ray_tracing_pipeline = options.ray_tracing_pipeline
            && RT_PIPELINE_EXTENSIONS.iter().all(|x| available.iter().any(|a| a.as_c_str() == *x))
            && {
                let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut accel).push_next(&mut rtp);
                unsafe { instance.get_physical_device_features2(physical, &mut f2) };
                let int64 = f2.features.shader_int64 == vk::TRUE;
                int64 && accel.acceleration_structure == vk::TRUE && rtp.ray_tracing_pipeline == vk::TRUE
            };
        // Doubles for the watertight triangle test's edge fallback in ray queries.
        // geometryShader: the G-buffer's fragment shader reads gl_PrimitiveID (SPIR-V declares the
        // Geometry capability for it); no geometry shader is used.
        // shaderStorageImageExtendedFormats: the visibility-buffer resolve writes RG16_SNORM.
        // shaderInt64: the ray-tracing peer's shaders take 64-bit device addresses.
        // textureCompressionBC: enabled where the device has it; a file with BC textures is
        // refused on a device without it (scene upload), with the option that avoids them.
        let supported = unsafe { instance.get_physical_device_features(physical) };
        let texture_compression_bc = supported.texture_compression_bc == vk::TRUE;
        let features = vk::PhysicalDeviceFeatures::default()
            .texture_compression_bc(texture_compression_bc)
            .shader_float64(true)
            .geometry_shader(true)
            .shader_storage_image_extended_formats(true)
            .shader_int64(ray_tracing_pipeline);
        let mut accel =
            vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default().acceleration_structure(true);
        let mut rtp = vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default().ray_tracing_pipeline(true);
        if ray_tracing_pipeline {
            device_extensions.extend(RT_PIPELINE_EXTENSIONS.iter().map(|x| x.as_ptr()));
        }
        let mut device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_extension_names(&device_extensions)
            .enabled_features(&features)
            .push_next(&mut f12)
            .push_next(&mut f13);
        if ray_tracing_pipeline {
            device_info = device_info.push_next(&mut accel).push_next(&mut rtp);
        }
        let device = unsafe { instance.create_device(physical, &device_info, None) }
            .map_err(|e| vk_err("creating the Vulkan device", e))?;
        let queue = unsafe { device.get_device_queue(family, 0) };
        let transfer = transfer_family.map(|t| (t, unsafe { device.get_device_queue(t, 0) }));
        let allocator = match Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: true,
            // Host-visible blocks are pinned and zeroed by the driver, which costs milliseconds per
            // 64 MiB (the default): small blocks, and large host buffers get their own.
            allocation_sizes: gpu_allocator::AllocationSizes::new(64 << 20, 4 << 20)
                .with_max_device_memblock_size(256 << 20),
        }) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: nothing was made on the new device.
                unsafe { device.destroy_device(None) };
                return Err(PlayError::new(Exit::Gpu, format!("creating the memory allocator failed: {e}")));
            }
        };
        // From here on the device goes with the last holder of its owner.
        let allocator = ManuallyDrop::new(Mutex::new(allocator));
        let owner = Arc::new(Owner { device: device.clone(), allocator, _instance: owned });
        let cache_data =
            options.pipeline_cache.as_ref().and_then(|p| std::fs::read(p).ok()).unwrap_or_default();
        let cache_info = vk::PipelineCacheCreateInfo::default().initial_data(&cache_data);
        // A stale or foreign cache blob is rejected by the driver's header check; start empty then.
        let pipeline_cache = unsafe { device.create_pipeline_cache(&cache_info, None) }
            .or_else(|_| unsafe {
                device.create_pipeline_cache(&vk::PipelineCacheCreateInfo::default(), None)
            })
            .map_err(|e| vk_err("creating the pipeline cache", e))?;
        Ok(Gpu {
            entry,
            instance,
            physical,
            properties,
            name,
            device,
            family,
            queue,
            transfer,
            validation,
            pipeline_cache,
            cache_path: options.pipeline_cache.clone(),
            ray_tracing_pipeline,
            storage_cap: options.max_storage_buffer,
            texture_compression_bc,
            owner,
        })
    }

    /// Validation errors reported so far.
    pub fn validation_errors(&self) -> u32 {
        self.validation.errors.load(Ordering::Relaxed)
    }

    /// What a benchmark record names the device by: name, driver and UUID.
    pub fn identity(&self) -> DeviceIdentity {
        let mut id = vk::PhysicalDeviceIDProperties::default();
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut props = vk::PhysicalDeviceProperties2::default().push_next(&mut id).push_next(&mut driver);
        // SAFETY: `physical` belongs to `instance`; both chained structs are core in Vulkan 1.2,
        // which device creation required.
        unsafe { self.instance.get_physical_device_properties2(self.physical, &mut props) };
        let text =
            |c: Result<&std::ffi::CStr, _>| c.map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
        let v = self.properties.driver_version;
        // NVIDIA packs 10.8.8.6 bits; everyone else follows the Vulkan version macros.
        let driver_version = if self.properties.vendor_id == 0x10de {
            format!("{}.{}.{:02}", v >> 22, (v >> 14) & 0xff, (v >> 6) & 0xff)
        } else {
            format!("{}.{}.{}", vk::api_version_major(v), vk::api_version_minor(v), vk::api_version_patch(v))
        };
        DeviceIdentity {
            name: self.name.clone(),
            driver_name: text(driver.driver_name_as_c_str()),
            driver_info: text(driver.driver_info_as_c_str()),
            driver_version,
            uuid: id.device_uuid.iter().map(|b| format!("{b:02x}")).collect(),
        }
    }

    /// Whether the device is Mesa's lavapipe (CPU).
    pub fn is_cpu(&self) -> bool {
        self.properties.device_type == vk::PhysicalDeviceType::CPU
    }

    /// Nanoseconds per timestamp tick.
    pub fn timestamp_period(&self) -> f64 {
        self.properties.limits.timestamp_period as f64
    }

    /// Largest storage buffer range the device allows (lavapipe: 128 MiB), or the cap of
    /// [`GpuOptions::max_storage_buffer`] when smaller.
    pub fn max_storage_buffer(&self) -> u64 {
        let device = self.properties.limits.max_storage_buffer_range as u64;
        self.storage_cap.map_or(device, |cap| cap.min(device))
    }

    /// What an object made on the device holds to release itself.
    pub(crate) fn owner(&self) -> Arc<Owner> {
        Arc::clone(&self.owner)
    }

    pub(crate) fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.owner.allocator()
    }

    /// The queue families resources are used from: with a dedicated transfer queue, uploaded
    /// resources are shared concurrently between it and the graphics queue (no ownership
    /// transfers needed).
    pub fn queue_families(&self) -> Vec<u32> {
        let mut f = vec![self.family];
        if let Some((t, _)) = self.transfer {
            f.push(t);
        }
        f
    }

    /// The family uploads are recorded for.
    pub fn upload_family(&self) -> u32 {
        self.transfer.map_or(self.family, |t| t.0)
    }

    /// A binary semaphore (swapchain acquire and present).
    pub fn binary_semaphore(&self) -> PlayResult<Semaphore> {
        let raw = unsafe { self.device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }
            .map_err(|e| vk_err("creating a semaphore", e))?;
        Ok(Semaphore { raw, owner: self.owner() })
    }

    /// A timeline semaphore starting at 0.
    pub fn timeline_semaphore(&self) -> PlayResult<Semaphore> {
        let mut kind = vk::SemaphoreTypeCreateInfo::default()
            .semaphore_type(vk::SemaphoreType::TIMELINE)
            .initial_value(0);
        let info = vk::SemaphoreCreateInfo::default().push_next(&mut kind);
        let raw = unsafe { self.device.create_semaphore(&info, None) }
            .map_err(|e| vk_err("creating a timeline semaphore", e))?;
        Ok(Semaphore { raw, owner: self.owner() })
    }

    /// Blocks until timeline `semaphore` reaches `value`.
    pub fn wait_timeline(&self, semaphore: vk::Semaphore, value: u64) -> PlayResult {
        let semaphores = [semaphore];
        let values = [value];
        let info = vk::SemaphoreWaitInfo::default().semaphores(&semaphores).values(&values);
        unsafe { self.device.wait_semaphores(&info, u64::MAX) }
            .map_err(|e| vk_err("waiting for a timeline semaphore", e))
    }

    /// Waits until the device is idle.
    pub fn wait_idle(&self) -> PlayResult {
        unsafe { self.device.device_wait_idle() }.map_err(|e| vk_err("waiting for the device", e))
    }
}

/// The Vulkan devices on this machine: (name, type, API version) each.
pub fn list_devices() -> PlayResult<Vec<(String, String, String)>> {
    let entry = loader().map_err(|e| unsupported(format!("no Vulkan loader ({e})")))?;
    let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_3);
    let instance =
        unsafe { entry.create_instance(&vk::InstanceCreateInfo::default().application_info(&app), None) }
            .map_err(|e| vk_err("creating the Vulkan instance", e))?;
    let devices = unsafe { instance.enumerate_physical_devices() }.unwrap_or_default();
    let list = devices
        .iter()
        .map(|&d| {
            let p = unsafe { instance.get_physical_device_properties(d) };
            let name = p.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
            let v = p.api_version;
            (
                name,
                format!("{:?}", p.device_type),
                format!(
                    "{}.{}.{}",
                    vk::api_version_major(v),
                    vk::api_version_minor(v),
                    vk::api_version_patch(v)
                ),
            )
        })
        .collect();
    unsafe { instance.destroy_instance(None) };
    Ok(list)
}

/// Picks (device, graphics+compute family, dedicated transfer family).
fn pick_device(
    instance: &ash::Instance,
    options: &GpuOptions,
) -> PlayResult<(vk::PhysicalDevice, u32, Option<u32>)> {
    let devices =
        unsafe { instance.enumerate_physical_devices() }.map_err(|e| vk_err("listing devices", e))?;
    if devices.is_empty() {
        return Err(unsupported(
            "no Vulkan device: install a GPU driver, or Mesa's lavapipe for the CPU (Debian: mesa-vulkan-drivers)",
        ));
    }
    let mut candidates = Vec::new();
    let mut rejected = Vec::new();
    for d in devices {
        let p = unsafe { instance.get_physical_device_properties(d) };
        let name = p.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
        if let Some(want) = &options.device
            && !name.to_lowercase().contains(&want.to_lowercase())
        {
            rejected.push(format!("{name} (not '{want}')"));
            continue;
        }
        if p.api_version < vk::API_VERSION_1_3 {
            rejected.push(format!(
                "{name} (Vulkan {}.{}, needs 1.3)",
                vk::api_version_major(p.api_version),
                vk::api_version_minor(p.api_version)
            ));
            continue;
        }
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f12).push_next(&mut f13);
        unsafe { instance.get_physical_device_features2(d, &mut f2) };
        let f10 = f2.features;
        let missing: Vec<&str> = [
            ("dynamicRendering", f13.dynamic_rendering),
            ("synchronization2", f13.synchronization2),
            ("maintenance4", f13.maintenance4),
            ("shaderFloat64", f10.shader_float64),
            ("geometryShader", f10.geometry_shader),
            ("shaderStorageImageExtendedFormats", f10.shader_storage_image_extended_formats),
            ("timelineSemaphore", f12.timeline_semaphore),
            ("bufferDeviceAddress", f12.buffer_device_address),
            ("scalarBlockLayout", f12.scalar_block_layout),
        ]
        .into_iter()
        .filter(|(_, on)| *on == vk::FALSE)
        .map(|(n, _)| n)
        .collect();
        if !missing.is_empty() {
            rejected.push(format!("{name} (lacks {})", missing.join(", ")));
            continue;
        }
        let families = unsafe { instance.get_physical_device_queue_family_properties(d) };
        let gc = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
        let Some(family) =
            families.iter().position(|f| f.queue_flags.contains(gc) && f.timestamp_valid_bits > 0)
        else {
            rejected.push(format!("{name} (no graphics and compute queue with timestamps)"));
            continue;
        };
        // A dedicated transfer queue copies at any texel granularity on every driver we know;
        // one that does not is ignored rather than special-cased.
        let unit = vk::Extent3D { width: 1, height: 1, depth: 1 };
        let transfer = families
            .iter()
            .position(|f| {
                f.queue_flags.contains(vk::QueueFlags::TRANSFER)
                    && !f.queue_flags.intersects(gc)
                    && f.min_image_transfer_granularity == unit
            })
            .map(|t| t as u32);
        let rank = match p.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 4,
        };
        candidates.push((rank, d, family as u32, transfer));
    }
    candidates.sort_by_key(|c| c.0);
    candidates
        .first()
        .map(|c| (c.1, c.2, c.3))
        .ok_or_else(|| unsupported(format!("no suitable Vulkan device: {}", rejected.join("; "))))
}

impl Drop for Gpu {
    /// Waits for the device, then saves and releases the pipeline cache. The device goes with
    /// the last holder of its [`Owner`]: this `Gpu` when the objects made on the device went
    /// first, as their holders make them. One that outlives the `Gpu` is counted as a validation
    /// error: the layer reports objects never released only when the device is destroyed, which
    /// would then come after whoever reads the counts (`Session::close`) has read them.
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            if let Some(path) = &self.cache_path
                && let Ok(data) = self.device.get_pipeline_cache_data(self.pipeline_cache)
            {
                if let Some(dir) = path.parent() {
                    let _ = std::fs::create_dir_all(dir);
                }
                let _ = std::fs::write(path, data);
            }
            // SAFETY: pipelines are made through a `&Gpu`, so none is being made now.
            self.device.destroy_pipeline_cache(self.pipeline_cache, None);
        }
        let outliving = Arc::strong_count(&self.owner) - 1;
        if outliving > 0 {
            self.validation.errors.fetch_add(1, Ordering::Relaxed);
            eprintln!("vulkan: {outliving} object(s) made on the device outlive its Gpu");
        }
    }
}

/// Default location of the pipeline cache: `$XDG_CACHE_HOME/kiln` or `~/.cache/kiln`.
pub fn default_cache_path() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    Some(base.join("kiln").join("pipelines.bin"))
}
