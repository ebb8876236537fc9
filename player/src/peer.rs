//! The peer of kiln's compute traversal: the driver's ray-tracing pipeline
//! (`VK_KHR_ray_tracing_pipeline`) over acceleration structures built at load from the baked
//! geometry (`VK_KHR_acceleration_structure`: one bottom-level structure of the file's triangles
//! in leaf order, so primitive indices equal kiln's triangle indices, and one instance). It traces
//! the same ray buffers into the same hit layout as [`crate::trace::RayQuery`], timed the same
//! way, so `--bench-rays` can compare the two on identical rays. Optional: absent when the device
//! lacks the extensions (lavapipe does).

use ash::vk;
use gpu_allocator::MemoryLocation;

use crate::error::{PlayResult, vk as vk_err};
use crate::gpu::{Buffer, CommandPool, Gpu, TimestampPool};
use crate::render::spirv;
use crate::trace::{GpuHit, GpuRay, timed_trace};

/// Push constants of `shaders/peer/trace.rgen`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Push {
    tlas: u64,
    rays: u64,
    hits: u64,
    count: u32,
    any_hit: u32,
}

/// Acceleration structures, pipeline and shader binding table.
pub struct RtPipelinePeer {
    accel: ash::khr::acceleration_structure::Device,
    rtp: ash::khr::ray_tracing_pipeline::Device,
    buffers: Vec<Buffer>,
    structures: Vec<vk::AccelerationStructureKHR>,
    tlas_address: u64,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    regions: [vk::StridedDeviceAddressRegionKHR; 3],
    pool: CommandPool,
    timestamps: TimestampPool,
    /// GPU milliseconds of the acceleration-structure build.
    pub build_ms: f64,
    /// Untimed traces recorded before each timed one (see [`crate::trace::WARMUP_TRACES`]).
    pub warmup: u32,
}

impl std::fmt::Debug for RtPipelinePeer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RtPipelinePeer").field("build_ms", &self.build_ms).finish()
    }
}

const ADDRESS: vk::BufferUsageFlags = vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;

impl RtPipelinePeer {
    /// Builds the structures over `corners` (three per triangle, leaf order) and the pipeline;
    /// `None` when the device has no ray-tracing pipeline enabled.
    pub fn new(gpu: &Gpu, corners: &[[f32; 3]]) -> PlayResult<Option<RtPipelinePeer>> {
        if !gpu.ray_tracing_pipeline || corners.is_empty() {
            return Ok(None);
        }
        let accel = ash::khr::acceleration_structure::Device::new(&gpu.instance, &gpu.device);
        let rtp = ash::khr::ray_tracing_pipeline::Device::new(&gpu.instance, &gpu.device);
        let mut pool = CommandPool::new(gpu, gpu.family)?;
        let timestamps = match TimestampPool::new(gpu, 2) {
            Ok(t) => t,
            Err(e) => {
                pool.destroy(gpu);
                return Err(e);
            }
        };
        let mut peer = RtPipelinePeer {
            accel,
            rtp,
            buffers: Vec::new(),
            structures: Vec::new(),
            tlas_address: 0,
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            regions: [vk::StridedDeviceAddressRegionKHR::default(); 3],
            pool,
            timestamps,
            build_ms: 0.0,
            warmup: 0,
        };
        match peer.build(gpu, corners).and_then(|()| peer.make_pipeline(gpu)) {
            Ok(()) => Ok(Some(peer)),
            Err(e) => {
                let _ = gpu.wait_idle();
                peer.destroy(gpu);
                Err(e)
            }
        }
    }

    fn host_buffer(
        &mut self,
        gpu: &Gpu,
        name: &str,
        bytes: &[u8],
        usage: vk::BufferUsageFlags,
    ) -> PlayResult<usize> {
        let mut b = Buffer::new(gpu, name, bytes.len() as u64, usage | ADDRESS, MemoryLocation::CpuToGpu)?;
        let written = b.write(bytes);
        self.buffers.push(b);
        written.map(|()| self.buffers.len() - 1)
    }

    fn device_buffer(
        &mut self,
        gpu: &Gpu,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
    ) -> PlayResult<usize> {
        self.buffers.push(Buffer::new(gpu, name, size, usage | ADDRESS, MemoryLocation::GpuOnly)?);
        Ok(self.buffers.len() - 1)
    }

    /// Creates one structure of `kind` sized for `geometry` × `primitives` and its scratch buffer;
    /// returns the handle, the scratch buffer's index and the structure's device address.
    fn structure(
        &mut self,
        gpu: &Gpu,
        kind: vk::AccelerationStructureTypeKHR,
        geometry: &vk::AccelerationStructureGeometryKHR,
        primitives: u32,
    ) -> PlayResult<(vk::AccelerationStructureKHR, usize, u64)> {
        let geometries = [*geometry];
        let info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(kind)
            .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geometries);
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        unsafe {
            self.accel.get_acceleration_structure_build_sizes(
                vk::AccelerationStructureBuildTypeKHR::DEVICE,
                &info,
                &[primitives],
                &mut sizes,
            )
        };
        let storage = self.device_buffer(
            gpu,
            "acceleration structure",
            sizes.acceleration_structure_size,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR,
        )?;
        let create = vk::AccelerationStructureCreateInfoKHR::default()
            .buffer(self.buffers[storage].raw)
            .size(sizes.acceleration_structure_size)
            .ty(kind);
        let handle = unsafe { self.accel.create_acceleration_structure(&create, None) }
            .map_err(|e| vk_err("creating an acceleration structure", e))?;
        self.structures.push(handle);
        // Scratch addresses must be aligned to minAccelerationStructureScratchOffsetAlignment
        // (at most 256 on every known driver): over-allocate and round the address up.
        let scratch = self.device_buffer(
            gpu,
            "acceleration structure scratch",
            sizes.build_scratch_size + 256,
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let address = unsafe {
            self.accel.get_acceleration_structure_device_address(
                &vk::AccelerationStructureDeviceAddressInfoKHR::default().acceleration_structure(handle),
            )
        };
        Ok((handle, scratch, address))
    }

    fn build(&mut self, gpu: &Gpu, corners: &[[f32; 3]]) -> PlayResult {
        let triangles = (corners.len() / 3) as u32;
        let input = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR;
        let vertices = self.host_buffer(gpu, "peer vertices", bytemuck::cast_slice(corners), input)?;
        let triangles_data = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
            .vertex_format(vk::Format::R32G32B32_SFLOAT)
            .vertex_data(vk::DeviceOrHostAddressConstKHR {
                device_address: self.buffers[vertices].address(gpu),
            })
            .vertex_stride(12)
            .max_vertex(corners.len() as u32 - 1)
            .index_type(vk::IndexType::NONE_KHR);
        let blas_geometry = vk::AccelerationStructureGeometryKHR::default()
            .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
            .geometry(vk::AccelerationStructureGeometryDataKHR { triangles: triangles_data })
            .flags(vk::GeometryFlagsKHR::OPAQUE);
        let (blas, blas_scratch, blas_address) =
            self.structure(gpu, vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, &blas_geometry, triangles)?;
        let instance = vk::AccelerationStructureInstanceKHR {
            transform: vk::TransformMatrixKHR {
                matrix: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            },
            instance_custom_index_and_mask: vk::Packed24_8::new(0, 0xff),
            instance_shader_binding_table_record_offset_and_flags: vk::Packed24_8::new(0, 0),
            acceleration_structure_reference: vk::AccelerationStructureReferenceKHR {
                device_handle: blas_address,
            },
        };
        // SAFETY: the instance record is plain data (64 bytes, no padding).
        let instance_bytes = unsafe {
            std::slice::from_raw_parts(
                (&instance as *const vk::AccelerationStructureInstanceKHR).cast::<u8>(),
                std::mem::size_of::<vk::AccelerationStructureInstanceKHR>(),
            )
        }
        .to_vec();
        let instances = self.host_buffer(gpu, "peer instance", &instance_bytes, input)?;
        let tlas_geometry = vk::AccelerationStructureGeometryKHR::default()
            .geometry_type(vk::GeometryTypeKHR::INSTANCES)
            .geometry(vk::AccelerationStructureGeometryDataKHR {
                instances: vk::AccelerationStructureGeometryInstancesDataKHR::default().data(
                    vk::DeviceOrHostAddressConstKHR { device_address: self.buffers[instances].address(gpu) },
                ),
            });
        let (tlas, tlas_scratch, tlas_address) =
            self.structure(gpu, vk::AccelerationStructureTypeKHR::TOP_LEVEL, &tlas_geometry, 1)?;
        self.tlas_address = tlas_address;

        let rec = self.pool.begin(gpu)?;
        rec.reset_timestamps(&self.timestamps);
        rec.timestamp(&self.timestamps, 0);
        for (structure, geometry, scratch, count) in
            [(blas, blas_geometry, blas_scratch, triangles), (tlas, tlas_geometry, tlas_scratch, 1)]
        {
            let kind = if structure == blas {
                vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL
            } else {
                vk::AccelerationStructureTypeKHR::TOP_LEVEL
            };
            let geometries = [geometry];
            let info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
                .ty(kind)
                .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
                .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
                .geometries(&geometries)
                .dst_acceleration_structure(structure)
                .scratch_data(vk::DeviceOrHostAddressKHR {
                    device_address: self.buffers[scratch].address(gpu).next_multiple_of(256),
                });
            let range = [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(count)];
            unsafe { self.accel.cmd_build_acceleration_structures(rec.cmd, &[info], &[&range[..]]) };
            // The top level reads the bottom level's build.
            rec.memory_barrier(
                vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR,
                vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR,
                vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR
                    | vk::PipelineStageFlags2::RAY_TRACING_SHADER_KHR,
                vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR,
            );
        }
        rec.timestamp(&self.timestamps, 1);
        self.pool.submit(gpu, &[], &[])?;
        self.pool.wait(gpu)?;
        let ns = self.timestamps.read_ns(gpu)?;
        self.build_ms = (ns[1] - ns[0]) * 1e-6;
        Ok(())
    }

    fn make_pipeline(&mut self, gpu: &Gpu) -> PlayResult {
        let push = vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::RAYGEN_KHR)
            .size(std::mem::size_of::<Push>() as u32);
        let pushes = [push];
        self.layout = unsafe {
            gpu.device.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&pushes),
                None,
            )
        }
        .map_err(|e| vk_err("creating the ray-tracing pipeline layout", e))?;
        let mut modules = Vec::new();
        for code in [spirv::PEER_RGEN, spirv::PEER_RMISS, spirv::PEER_RCHIT] {
            let words: Vec<u32> =
                code.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
            match unsafe {
                gpu.device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&words), None)
            } {
                Ok(m) => modules.push(m),
                Err(e) => {
                    for m in modules {
                        unsafe { gpu.device.destroy_shader_module(m, None) };
                    }
                    return Err(vk_err("creating a ray-tracing shader module", e));
                }
            }
        }
        let main = c"main";
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::RAYGEN_KHR)
                .module(modules[0])
                .name(main),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::MISS_KHR)
                .module(modules[1])
                .name(main),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::CLOSEST_HIT_KHR)
                .module(modules[2])
                .name(main),
        ];
        let general = |i: u32| {
            vk::RayTracingShaderGroupCreateInfoKHR::default()
                .ty(vk::RayTracingShaderGroupTypeKHR::GENERAL)
                .general_shader(i)
                .closest_hit_shader(vk::SHADER_UNUSED_KHR)
                .any_hit_shader(vk::SHADER_UNUSED_KHR)
                .intersection_shader(vk::SHADER_UNUSED_KHR)
        };
        let groups = [
            general(0),
            general(1),
            vk::RayTracingShaderGroupCreateInfoKHR::default()
                .ty(vk::RayTracingShaderGroupTypeKHR::TRIANGLES_HIT_GROUP)
                .general_shader(vk::SHADER_UNUSED_KHR)
                .closest_hit_shader(2)
                .any_hit_shader(vk::SHADER_UNUSED_KHR)
                .intersection_shader(vk::SHADER_UNUSED_KHR),
        ];
        let info = vk::RayTracingPipelineCreateInfoKHR::default()
            .stages(&stages)
            .groups(&groups)
            .max_pipeline_ray_recursion_depth(1)
            .layout(self.layout);
        let created = unsafe {
            self.rtp.create_ray_tracing_pipelines(
                vk::DeferredOperationKHR::null(),
                gpu.pipeline_cache,
                &[info],
                None,
            )
        };
        for m in modules {
            unsafe { gpu.device.destroy_shader_module(m, None) };
        }
        self.pipeline = match created {
            Ok(p) => p[0],
            Err((_, e)) => return Err(vk_err("creating the ray-tracing pipeline", e)),
        };
        // Shader binding table: raygen, miss and hit records, each at the base alignment.
        let mut props = vk::PhysicalDeviceRayTracingPipelinePropertiesKHR::default();
        let mut p2 = vk::PhysicalDeviceProperties2::default().push_next(&mut props);
        unsafe { gpu.instance.get_physical_device_properties2(gpu.physical, &mut p2) };
        let handle = props.shader_group_handle_size as usize;
        let stride = (handle as u64).next_multiple_of(props.shader_group_handle_alignment.max(1) as u64);
        let base = props.shader_group_base_alignment.max(1) as u64;
        let handles =
            unsafe { self.rtp.get_ray_tracing_shader_group_handles(self.pipeline, 0, 3, handle * 3) }
                .map_err(|e| vk_err("reading shader group handles", e))?;
        let mut table = vec![0u8; (base * 3) as usize];
        for g in 0..3 {
            let at = (g as u64 * base) as usize;
            table[at..at + handle].copy_from_slice(&handles[g * handle..(g + 1) * handle]);
        }
        // One extra base alignment lets the table start aligned whatever the allocation offset.
        let mut b = Buffer::new(
            gpu,
            "shader binding table",
            table.len() as u64 + base,
            vk::BufferUsageFlags::SHADER_BINDING_TABLE_KHR | ADDRESS,
            MemoryLocation::CpuToGpu,
        )?;
        let address = b.address(gpu);
        let start = address.next_multiple_of(base);
        let skip = (start - address) as usize;
        let mut bytes = vec![0u8; skip];
        bytes.extend_from_slice(&table);
        let written = b.write(&bytes);
        self.buffers.push(b);
        written?;
        let region = |g: u64| vk::StridedDeviceAddressRegionKHR {
            device_address: start + g * base,
            stride,
            size: stride,
        };
        // The raygen region's size must equal its stride.
        self.regions = [region(0), region(1), region(2)];
        Ok(())
    }

    /// Traces `rays` (closest hit, or any hit); returns one hit per ray and the GPU milliseconds
    /// of the trace alone.
    pub fn trace(&mut self, gpu: &Gpu, rays: &[GpuRay], any_hit: bool) -> PlayResult<(Vec<GpuHit>, f64)> {
        let this = &*self;
        timed_trace(
            gpu,
            &this.pool,
            &this.timestamps,
            rays,
            ADDRESS,
            this.warmup,
            |rec, input, output, count| {
                let push = Push {
                    tlas: this.tlas_address,
                    rays: input.address(gpu),
                    hits: output.address(gpu),
                    count,
                    any_hit: any_hit as u32,
                };
                unsafe {
                    gpu.device.cmd_bind_pipeline(
                        rec.cmd,
                        vk::PipelineBindPoint::RAY_TRACING_KHR,
                        this.pipeline,
                    );
                    gpu.device.cmd_push_constants(
                        rec.cmd,
                        this.layout,
                        vk::ShaderStageFlags::RAYGEN_KHR,
                        0,
                        bytemuck::bytes_of(&push),
                    );
                    this.rtp.cmd_trace_rays(
                        rec.cmd,
                        &this.regions[0],
                        &this.regions[1],
                        &this.regions[2],
                        &vk::StridedDeviceAddressRegionKHR::default(),
                        count,
                        1,
                        1,
                    );
                }
                vk::PipelineStageFlags2::RAY_TRACING_SHADER_KHR
            },
        )
    }

    /// Releases everything (the GPU must be idle).
    pub fn destroy(&mut self, gpu: &Gpu) {
        unsafe {
            if self.pipeline != vk::Pipeline::null() {
                gpu.device.destroy_pipeline(self.pipeline, None);
            }
            if self.layout != vk::PipelineLayout::null() {
                gpu.device.destroy_pipeline_layout(self.layout, None);
            }
            for s in self.structures.drain(..) {
                self.accel.destroy_acceleration_structure(s, None);
            }
        }
        for b in &mut self.buffers {
            b.destroy(gpu);
        }
        self.buffers.clear();
        self.timestamps.destroy(gpu);
        self.pool.destroy(gpu);
    }
}
