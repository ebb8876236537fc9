//! Vulkan compute for the compiler's bakes: a device, buffers, compute kernels and one-shot
//! command submissions, nothing else. The player has its own Vulkan layer (`kiln-player`'s
//! `gpu`); this crate keeps the compiler free of it (and of windows, swapchains and passes), and
//! the player free of the bakes.
//!
//! Everything is synchronous: [`Compute::run`] records commands, submits them and waits.

use std::ffi::{CStr, c_void};
use std::sync::atomic::{AtomicU32, Ordering};

pub use ash::vk;

/// What went wrong, in words a user can act on.
#[derive(Debug, Clone)]
pub struct Error(pub String);

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Error {}

/// Results of this crate.
pub type Result<T> = std::result::Result<T, Error>;

fn vk_err(what: &str, e: vk::Result) -> Error {
    Error(format!("{what} failed: {e:?}"))
}

/// Which devices [`Compute::new`] may take.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Take a CPU implementation (lavapipe) when no GPU is present (tests; a bake on the CPU's
    /// own code is faster than one through lavapipe).
    pub allow_cpu: bool,
    /// Enable the Khronos validation layer and count its errors ([`Compute::validation_errors`]).
    pub validate: bool,
}

/// The instance and device, destroyed when the last of the [`Compute`], [`Buffer`]s and
/// [`Kernel`]s made on them goes.
struct Owner {
    instance: ash::Instance,
    device: ash::Device,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// The validation error counter the messenger writes (boxed: its address is the messenger's
    /// user data).
    _errors: std::sync::Arc<AtomicU32>,
}

impl Drop for Owner {
    fn drop(&mut self) {
        // SAFETY: nothing made on the device is left (every holder of an `Arc<Owner>` is gone,
        // and `Compute`'s drop waited for the device to go idle).
        unsafe {
            self.device.destroy_device(None);
            if let Some((u, m)) = &self.debug {
                u.destroy_debug_utils_messenger(*m, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// A Vulkan device with one compute queue.
pub struct Compute {
    _entry: ash::Entry,
    owner: std::sync::Arc<Owner>,
    device: ash::Device,
    /// Held while the queue or the command pool is used (Vulkan leaves their synchronisation to
    /// the caller).
    lock: std::sync::Mutex<()>,
    queue: vk::Queue,
    pool: vk::CommandPool,
    memory: vk::PhysicalDeviceMemoryProperties,
    name: String,
    cpu: bool,
    max_buffer: u64,
    errors: std::sync::Arc<AtomicU32>,
}

impl std::fmt::Debug for Compute {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Compute").field("name", &self.name).field("cpu", &self.cpu).finish()
    }
}

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        // SAFETY: `user` is the counter boxed in `Compute`, which outlives the messenger; the
        // loader passes valid callback data.
        unsafe {
            (*(user as *const AtomicU32)).fetch_add(1, Ordering::Relaxed);
            if !data.is_null() && !(*data).p_message.is_null() {
                eprintln!("vulkan validation error: {}", CStr::from_ptr((*data).p_message).to_string_lossy());
            }
        }
    }
    vk::FALSE
}

/// The Vulkan loader, loaded once per process (unloading and reloading NVIDIA's driver many
/// times in one process fails; see the player's `gpu::loader`).
fn loader() -> Result<ash::Entry> {
    static LOADED: std::sync::OnceLock<std::result::Result<ash::Entry, String>> = std::sync::OnceLock::new();
    LOADED
        .get_or_init(|| {
            // SAFETY: loads the system's Vulkan loader; its symbols are called only through ash.
            unsafe { ash::Entry::load() }.map_err(|e| e.to_string())
        })
        .clone()
        .map_err(|e| Error(format!("no Vulkan loader ({e}); install a GPU driver (Debian: libvulkan1)")))
}

impl Compute {
    /// Opens the first GPU with 64-bit floats and integers in shaders (a discrete one first),
    /// or, with `allow_cpu`, a CPU implementation if there is no GPU.
    pub fn new(options: &Options) -> Result<Compute> {
        let entry = loader()?;
        let mut layers = Vec::new();
        let mut extensions = Vec::new();
        if options.validate {
            // SAFETY: plain query.
            let available = unsafe { entry.enumerate_instance_layer_properties() }
                .map_err(|e| vk_err("listing Vulkan layers", e))?;
            if !available.iter().any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER)) {
                return Err(Error(
                    "the Khronos validation layer is not installed (Debian: vulkan-validationlayers)".into(),
                ));
            }
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        let app = vk::ApplicationInfo::default().application_name(c"kiln").api_version(vk::API_VERSION_1_2);
        let info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        // SAFETY: every pointer in `info` lives until the call returns.
        let instance = unsafe { entry.create_instance(&info, None) }.map_err(|e| match e {
            vk::Result::ERROR_INCOMPATIBLE_DRIVER => Error("no Vulkan driver found".into()),
            e => vk_err("creating the Vulkan instance", e),
        })?;
        let errors = std::sync::Arc::new(AtomicU32::new(0));
        let debug = if options.validate {
            let utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(std::sync::Arc::as_ptr(&errors) as *mut c_void);
            // SAFETY: `info` is valid; the counter outlives the messenger.
            match unsafe { utils.create_debug_utils_messenger(&info, None) } {
                Ok(m) => Some((utils, m)),
                Err(e) => {
                    // SAFETY: nothing was created from the instance.
                    unsafe { instance.destroy_instance(None) };
                    return Err(vk_err("creating the debug messenger", e));
                }
            }
        } else {
            None
        };
        let destroy = |debug: &Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>| {
            // SAFETY: the messenger and instance were created above and nothing else uses them.
            unsafe {
                if let Some((u, m)) = debug {
                    u.destroy_debug_utils_messenger(*m, None);
                }
                instance.destroy_instance(None);
            }
        };
        let picked = match pick(&instance, options.allow_cpu) {
            Ok(p) => p,
            Err(e) => {
                destroy(&debug);
                return Err(e);
            }
        };
        let (physical, family, name, cpu, max_buffer) = picked;
        let priorities = [1.0f32];
        let queues =
            [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
        let features = vk::PhysicalDeviceFeatures::default().shader_float64(true).shader_int64(true);
        let info = vk::DeviceCreateInfo::default().queue_create_infos(&queues).enabled_features(&features);
        // SAFETY: `info` and what it points to live until the call returns.
        let device = match unsafe { instance.create_device(physical, &info, None) } {
            Ok(d) => d,
            Err(e) => {
                destroy(&debug);
                return Err(vk_err("creating the Vulkan device", e));
            }
        };
        // SAFETY: the family was created with one queue.
        let queue = unsafe { device.get_device_queue(family, 0) };
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and info.
        let pool = match unsafe { device.create_command_pool(&pool_info, None) } {
            Ok(p) => p,
            Err(e) => {
                // SAFETY: the device is idle and owns nothing yet.
                unsafe { device.destroy_device(None) };
                destroy(&debug);
                return Err(vk_err("creating a command pool", e));
            }
        };
        // SAFETY: plain query.
        let memory = unsafe { instance.get_physical_device_memory_properties(physical) };
        let owner =
            std::sync::Arc::new(Owner { instance, device: device.clone(), debug, _errors: errors.clone() });
        Ok(Compute {
            _entry: entry,
            owner,
            device,
            lock: std::sync::Mutex::new(()),
            queue,
            pool,
            memory,
            name,
            cpu,
            max_buffer,
            errors,
        })
    }

    /// The device's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Whether the device is a CPU implementation.
    pub fn is_cpu(&self) -> bool {
        self.cpu
    }

    /// The largest storage buffer a kernel may bind, bytes.
    pub fn max_buffer(&self) -> u64 {
        self.max_buffer
    }

    /// Validation errors reported so far (0 without [`Options::validate`]).
    pub fn validation_errors(&self) -> u32 {
        self.errors.load(Ordering::Relaxed)
    }

    /// A storage buffer of `size` bytes (at least 4) in `memory`.
    pub fn buffer(&self, size: u64, memory: Memory) -> Result<Buffer> {
        let size = size.max(4).next_multiple_of(4);
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::TRANSFER_SRC
            | vk::BufferUsageFlags::TRANSFER_DST;
        let info = vk::BufferCreateInfo::default().size(size).usage(usage);
        // SAFETY: valid device and info.
        let buffer =
            unsafe { self.device.create_buffer(&info, None) }.map_err(|e| vk_err("creating a buffer", e))?;
        // SAFETY: `buffer` was just created on this device.
        let req = unsafe { self.device.get_buffer_memory_requirements(buffer) };
        let wanted = match memory {
            Memory::Device => vk::MemoryPropertyFlags::DEVICE_LOCAL,
            Memory::Upload => vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT,
            Memory::Readback => {
                vk::MemoryPropertyFlags::HOST_VISIBLE
                    | vk::MemoryPropertyFlags::HOST_COHERENT
                    | vk::MemoryPropertyFlags::HOST_CACHED
            }
        };
        let fallback = match memory {
            Memory::Device => vk::MemoryPropertyFlags::empty(),
            _ => vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT,
        };
        let destroy = || {
            // SAFETY: the buffer is unused.
            unsafe { self.device.destroy_buffer(buffer, None) }
        };
        let Some(kind) = self
            .memory_type(req.memory_type_bits, wanted)
            .or_else(|| self.memory_type(req.memory_type_bits, fallback))
        else {
            destroy();
            return Err(Error(format!("no Vulkan memory type for a {memory:?} buffer")));
        };
        let alloc = vk::MemoryAllocateInfo::default().allocation_size(req.size).memory_type_index(kind);
        // SAFETY: valid device and info.
        let mem = match unsafe { self.device.allocate_memory(&alloc, None) } {
            Ok(m) => m,
            Err(e) => {
                destroy();
                return Err(vk_err(&format!("allocating {} MiB of GPU-visible memory", size >> 20), e));
            }
        };
        // SAFETY: the memory fits the buffer's requirements and is bound once.
        let bound = unsafe { self.device.bind_buffer_memory(buffer, mem, 0) };
        let mapped = match (bound, memory) {
            (Err(e), _) => Err(vk_err("binding buffer memory", e)),
            (Ok(()), Memory::Device) => Ok(None),
            // SAFETY: host-visible memory, mapped whole once, unmapped when freed.
            (Ok(()), _) => {
                unsafe { self.device.map_memory(mem, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty()) }
                    .map(|p| Some(p as *mut u8))
                    .map_err(|e| vk_err("mapping buffer memory", e))
            }
        };
        match mapped {
            Ok(mapped) => Ok(Buffer {
                buffer,
                memory: mem,
                kind: memory,
                size,
                mapped,
                device: self.device.clone(),
                _owner: self.owner.clone(),
            }),
            Err(e) => {
                destroy();
                // SAFETY: the memory is no longer bound to a live buffer.
                unsafe { self.device.free_memory(mem, None) };
                Err(e)
            }
        }
    }

    fn memory_type(&self, bits: u32, flags: vk::MemoryPropertyFlags) -> Option<u32> {
        (0..self.memory.memory_type_count).find(|&i| {
            bits & (1 << i) != 0 && self.memory.memory_types[i as usize].property_flags.contains(flags)
        })
    }

    /// A compute kernel from SPIR-V whose set 0 holds `bindings` storage buffers, bindings 0 to
    /// `bindings` − 1.
    pub fn kernel(&self, spirv: &[u8], bindings: u32) -> Result<Kernel> {
        let words: Vec<u32> =
            spirv.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        let d = &self.device;
        // SAFETY (each call below): valid device and create infos that live through the call;
        // objects created before a failure are destroyed by `Kernel`'s drop.
        let module =
            unsafe { d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&words), None) }
                .map_err(|e| vk_err("creating a shader module", e))?;
        let mut k = Kernel {
            device: d.clone(),
            _owner: self.owner.clone(),
            module,
            set_layout: vk::DescriptorSetLayout::null(),
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            bindings,
        };
        let list: Vec<_> = (0..bindings)
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        k.set_layout = unsafe {
            d.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&list),
                None,
            )
        }
        .map_err(|e| vk_err("creating a descriptor set layout", e))?;
        let sets = [k.set_layout];
        k.layout = unsafe {
            d.create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().set_layouts(&sets), None)
        }
        .map_err(|e| vk_err("creating a pipeline layout", e))?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main");
        let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(k.layout)];
        k.pipeline = unsafe { d.create_compute_pipelines(vk::PipelineCache::null(), &info, None) }
            .map_err(|(_, e)| vk_err("creating a compute pipeline", e))?[0];
        Ok(k)
    }

    /// Records commands with `record`, submits them and waits for them to finish.
    pub fn run(&self, record: impl FnOnce(&mut Commands) -> Result<()>) -> Result<()> {
        // SAFETY: the work is waited for before the buffers `record` borrowed can go.
        unsafe { self.submit(record) }?.wait()
    }

    /// Records commands with `record` and submits them; [`Pending::wait`] waits for them. Work
    /// submitted later runs after it (each dispatch, copy and fill begins with a full barrier,
    /// whose scope reaches back over earlier submissions to the queue).
    ///
    /// # Safety
    ///
    /// Every buffer and kernel the commands use must outlive the returned [`Pending`] (be neither
    /// dropped nor read through [`Buffer::bytes`] before it is waited for or dropped).
    pub unsafe fn submit(&self, record: impl FnOnce(&mut Commands) -> Result<()>) -> Result<Pending<'_>> {
        let d = &self.device;
        let _guard = self.lock.lock().unwrap_or_else(|e| e.into_inner());
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: valid pool.
        let cmd = unsafe { d.allocate_command_buffers(&info) }
            .map_err(|e| vk_err("allocating a command buffer", e))?[0];
        let mut pending = Pending { compute: self, cmd, pools: Vec::new(), fence: vk::Fence::null() };
        let mut c = Commands { device: d, max_range: self.max_buffer, cmd, pools: Vec::new() };
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: a fresh command buffer, recorded once.
        unsafe { d.begin_command_buffer(cmd, &begin) }
            .map_err(|e| vk_err("beginning a command buffer", e))?;
        let recorded = record(&mut c);
        pending.pools = std::mem::take(&mut c.pools);
        recorded?;
        // SAFETY: recording began above.
        unsafe { d.end_command_buffer(cmd) }.map_err(|e| vk_err("ending a command buffer", e))?;
        // SAFETY: valid device.
        pending.fence = unsafe { d.create_fence(&vk::FenceCreateInfo::default(), None) }
            .map_err(|e| vk_err("creating a fence", e))?;
        let cmds = [cmd];
        let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
        // SAFETY: the command buffer is complete; the fence is unsignalled.
        if let Err(e) = unsafe { d.queue_submit(self.queue, &submit, pending.fence) } {
            // SAFETY: never submitted: nothing waits on the fence.
            unsafe { d.destroy_fence(pending.fence, None) };
            pending.fence = vk::Fence::null();
            return Err(vk_err("submitting GPU work", e));
        }
        Ok(pending)
    }
}

/// Submitted work ([`Compute::submit`]); dropping it waits too.
pub struct Pending<'a> {
    compute: &'a Compute,
    cmd: vk::CommandBuffer,
    pools: Vec<vk::DescriptorPool>,
    fence: vk::Fence,
}

impl std::fmt::Debug for Pending<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pending").finish()
    }
}

impl Pending<'_> {
    /// Waits for the work to finish.
    pub fn wait(mut self) -> Result<()> {
        self.finish()
    }

    fn finish(&mut self) -> Result<()> {
        let d = &self.compute.device;
        let mut result = Ok(());
        if self.fence != vk::Fence::null() {
            // SAFETY: the fence was submitted with the work.
            result = unsafe { d.wait_for_fences(&[self.fence], true, u64::MAX) }
                .map_err(|e| vk_err("waiting for the GPU", e));
            if result.is_err() {
                // SAFETY: after a failure nothing may still run; wait to be sure before freeing.
                let _ = unsafe { d.device_wait_idle() };
            }
            // SAFETY: signalled (or the device is idle).
            unsafe { d.destroy_fence(self.fence, None) };
            self.fence = vk::Fence::null();
        }
        if self.cmd != vk::CommandBuffer::null() {
            let _guard = self.compute.lock.lock().unwrap_or_else(|e| e.into_inner());
            // SAFETY: the work finished, so its command buffer and descriptor pools are free.
            unsafe {
                d.free_command_buffers(self.compute.pool, &[self.cmd]);
                for p in self.pools.drain(..) {
                    d.destroy_descriptor_pool(p, None);
                }
            }
            self.cmd = vk::CommandBuffer::null();
        }
        result
    }
}

impl Drop for Pending<'_> {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

impl Drop for Compute {
    fn drop(&mut self) {
        // SAFETY: no `Pending` is left (each borrows the `Compute`), so no command buffer of the
        // pool is in use; the device itself goes with the last `Arc<Owner>`.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.pool, None);
        }
    }
}

/// The physical device: (device, compute family, name, is a CPU, largest storage buffer).
fn pick(instance: &ash::Instance, allow_cpu: bool) -> Result<(vk::PhysicalDevice, u32, String, bool, u64)> {
    // SAFETY: plain queries on a valid instance.
    let devices =
        unsafe { instance.enumerate_physical_devices() }.map_err(|e| vk_err("listing Vulkan devices", e))?;
    let mut found = Vec::new();
    let mut rejected = Vec::new();
    for d in devices {
        // SAFETY: as above.
        let (p, f, families) = unsafe {
            (
                instance.get_physical_device_properties(d),
                instance.get_physical_device_features(d),
                instance.get_physical_device_queue_family_properties(d),
            )
        };
        let name = p.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
        let cpu = p.device_type == vk::PhysicalDeviceType::CPU;
        if p.api_version < vk::API_VERSION_1_2 {
            rejected.push(format!(
                "{name} (Vulkan {}.{}, needs 1.2)",
                vk::api_version_major(p.api_version),
                vk::api_version_minor(p.api_version)
            ));
            continue;
        }
        if cpu && !allow_cpu {
            rejected.push(format!("{name} (a CPU implementation)"));
            continue;
        }
        if f.shader_float64 == vk::FALSE || f.shader_int64 == vk::FALSE {
            rejected.push(format!("{name} (no 64-bit floats or integers in shaders)"));
            continue;
        }
        let Some(family) = families.iter().position(|q| q.queue_flags.contains(vk::QueueFlags::COMPUTE))
        else {
            rejected.push(format!("{name} (no compute queue)"));
            continue;
        };
        let rank = match p.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 2,
        };
        found.push((rank, d, family as u32, name, cpu, p.limits.max_storage_buffer_range as u64));
    }
    found.sort_by_key(|f| f.0);
    found.into_iter().next().map(|f| (f.1, f.2, f.3, f.4, f.5)).ok_or_else(|| {
        Error(if rejected.is_empty() {
            "no Vulkan device".into()
        } else {
            format!("no usable Vulkan device: {}", rejected.join("; "))
        })
    })
}

/// Where a buffer lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Memory {
    /// GPU memory, not mapped.
    Device,
    /// Host memory the GPU reads: mapped, written by the CPU.
    Upload,
    /// Host memory the GPU writes: mapped, read by the CPU (cached where the device offers it).
    Readback,
}

/// A storage buffer and its own memory.
pub struct Buffer {
    buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    kind: Memory,
    size: u64,
    mapped: Option<*mut u8>,
    device: ash::Device,
    _owner: std::sync::Arc<Owner>,
}

// SAFETY: the mapping is plain host memory owned by this buffer; access goes through `&self` /
// `&mut self` like any other owned bytes.
unsafe impl Send for Buffer {}
// SAFETY: as above; shared access only reads.
unsafe impl Sync for Buffer {}

impl std::fmt::Debug for Buffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Buffer").field("size", &self.size).finish()
    }
}

impl Buffer {
    /// Size, bytes.
    pub fn size(&self) -> u64 {
        self.size
    }

    /// Where it lives.
    pub fn memory(&self) -> Memory {
        self.kind
    }

    /// The mapped bytes of an [`Memory::Upload`] or [`Memory::Readback`] buffer.
    pub fn bytes(&self) -> &[u8] {
        match self.mapped {
            // SAFETY: the mapping covers `size` bytes and lives as long as the buffer; the GPU
            // writes it only in work that `Compute::submit`'s contract has the caller wait for
            // before reading (`Compute::run` waits itself).
            Some(p) => unsafe { std::slice::from_raw_parts(p, self.size as usize) },
            None => &[],
        }
    }

    /// The mapped bytes, writable.
    pub fn bytes_mut(&mut self) -> &mut [u8] {
        match self.mapped {
            // SAFETY: as for `bytes`, exclusively borrowed.
            Some(p) => unsafe { std::slice::from_raw_parts_mut(p, self.size as usize) },
            None => &mut [],
        }
    }

    /// Copies `data` to the start of a mapped buffer.
    pub fn write<T: bytemuck::Pod>(&mut self, data: &[T]) -> Result<()> {
        let src: &[u8] = bytemuck::cast_slice(data);
        let dst = self.bytes_mut();
        if src.len() > dst.len() {
            return Err(Error(format!("{} bytes do not fit a buffer of {}", src.len(), dst.len())));
        }
        dst[..src.len()].copy_from_slice(src);
        Ok(())
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: no submitted work uses the buffer (`Compute::run` waits for its work).
        unsafe {
            if self.mapped.is_some() {
                self.device.unmap_memory(self.memory);
            }
            self.device.destroy_buffer(self.buffer, None);
            self.device.free_memory(self.memory, None);
        }
    }
}

/// A compute pipeline and its layout.
pub struct Kernel {
    device: ash::Device,
    _owner: std::sync::Arc<Owner>,
    module: vk::ShaderModule,
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    bindings: u32,
}

impl std::fmt::Debug for Kernel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Kernel").field("bindings", &self.bindings).finish()
    }
}

impl Drop for Kernel {
    fn drop(&mut self) {
        // SAFETY: null handles are ignored; no submitted work uses the kernel any more.
        unsafe {
            self.device.destroy_pipeline(self.pipeline, None);
            self.device.destroy_pipeline_layout(self.layout, None);
            self.device.destroy_descriptor_set_layout(self.set_layout, None);
            self.device.destroy_shader_module(self.module, None);
        }
    }
}

/// Commands being recorded by [`Compute::run`].
pub struct Commands<'a> {
    device: &'a ash::Device,
    max_range: u64,
    cmd: vk::CommandBuffer,
    pools: Vec<vk::DescriptorPool>,
}

impl std::fmt::Debug for Commands<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Commands").finish()
    }
}

impl Commands<'_> {
    /// Runs `kernel` over `groups` workgroups with `buffers` bound in order, after all earlier
    /// commands' writes (a full barrier before it).
    pub fn dispatch(&mut self, kernel: &Kernel, buffers: &[&Buffer], groups: [u32; 3]) -> Result<()> {
        if buffers.len() != kernel.bindings as usize {
            return Err(Error(format!(
                "{} buffers for a kernel of {} bindings",
                buffers.len(),
                kernel.bindings
            )));
        }
        let d = self.device;
        let sizes = [vk::DescriptorPoolSize::default()
            .ty(vk::DescriptorType::STORAGE_BUFFER)
            .descriptor_count(kernel.bindings)];
        let info = vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes);
        // SAFETY: valid device and info; the pool is destroyed after the work finishes.
        let pool = unsafe { d.create_descriptor_pool(&info, None) }
            .map_err(|e| vk_err("creating a descriptor pool", e))?;
        self.pools.push(pool);
        let layouts = [kernel.set_layout];
        let alloc = vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts);
        // SAFETY: the pool has room for this one set.
        let set = unsafe { d.allocate_descriptor_sets(&alloc) }
            .map_err(|e| vk_err("allocating a descriptor set", e))?[0];
        // Bound up to the storage-buffer range: a pooled buffer may be larger than its use.
        let infos: Vec<[vk::DescriptorBufferInfo; 1]> = buffers
            .iter()
            .map(|b| {
                [vk::DescriptorBufferInfo::default()
                    .buffer(b.buffer)
                    .offset(0)
                    .range(b.size.min(self.max_range))]
            })
            .collect();
        let writes: Vec<_> = infos
            .iter()
            .enumerate()
            .map(|(i, info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(i as u32)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .buffer_info(info)
            })
            .collect();
        // SAFETY: the set and buffers are valid; the command buffer is recording.
        unsafe {
            d.update_descriptor_sets(&writes, &[]);
            self.barrier();
            d.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::COMPUTE, kernel.pipeline);
            d.cmd_bind_descriptor_sets(
                self.cmd,
                vk::PipelineBindPoint::COMPUTE,
                kernel.layout,
                0,
                &[set],
                &[],
            );
            d.cmd_dispatch(self.cmd, groups[0], groups[1], groups[2]);
        }
        Ok(())
    }

    /// Copies `size` bytes from the start of `src` to the start of `dst`, after earlier writes.
    pub fn copy(&mut self, src: &Buffer, dst: &Buffer, size: u64) {
        if size == 0 {
            return;
        }
        let region = [vk::BufferCopy::default().size(size)];
        // SAFETY: both buffers hold at least `size` bytes (callers size them); recording.
        unsafe {
            self.barrier();
            self.device.cmd_copy_buffer(self.cmd, src.buffer, dst.buffer, &region);
        }
    }

    /// Fills the first `size` bytes (a multiple of 4) of `buffer` with zeros, after earlier work.
    pub fn zero(&mut self, buffer: &Buffer, size: u64) {
        if size == 0 {
            return;
        }
        // SAFETY: recording; the range lies inside the buffer.
        unsafe {
            self.barrier();
            self.device.cmd_fill_buffer(self.cmd, buffer.buffer, 0, size, 0);
        }
    }

    /// Orders everything before against everything after (the bakes' commands are few and
    /// large: a full barrier costs nothing that matters).
    fn barrier(&mut self) {
        let all = vk::AccessFlags::SHADER_READ
            | vk::AccessFlags::SHADER_WRITE
            | vk::AccessFlags::TRANSFER_READ
            | vk::AccessFlags::TRANSFER_WRITE
            | vk::AccessFlags::HOST_READ
            | vk::AccessFlags::HOST_WRITE;
        let b = [vk::MemoryBarrier::default().src_access_mask(all).dst_access_mask(all)];
        let stages = vk::PipelineStageFlags::COMPUTE_SHADER
            | vk::PipelineStageFlags::TRANSFER
            | vk::PipelineStageFlags::HOST;
        // SAFETY: recording.
        unsafe {
            self.device.cmd_pipeline_barrier(
                self.cmd,
                stages,
                stages,
                vk::DependencyFlags::empty(),
                &b,
                &[],
                &[],
            )
        };
    }

    /// Makes the GPU's writes visible to the host once the work finishes (call last).
    pub fn to_host(&mut self) {
        self.barrier();
    }
}
