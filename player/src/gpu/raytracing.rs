//! The driver's ray tracing: acceleration structures (`VK_KHR_acceleration_structure`) over a
//! triangle list, and a ray-tracing pipeline (`VK_KHR_ray_tracing_pipeline`) with its shader
//! binding table. Both need the extensions enabled ([`Gpu::ray_tracing_pipeline`]).

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::pipelines::{Pipeline, shader_module};
use super::{Buffer, Gpu, Owner, Recorder};
use crate::error::{Exit, PlayError, PlayResult, vk as vk_err};

const ADDRESS: vk::BufferUsageFlags = vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;

/// Scratch addresses must be aligned to minAccelerationStructureScratchOffsetAlignment (at most
/// 256 on every known driver): scratch buffers are over-allocated by this and the address
/// rounded up.
const SCRATCH_ALIGNMENT: u64 = 256;

/// One level's structure, what it is built from, and where its build scratch starts.
#[derive(Clone, Copy)]
struct Level {
    handle: vk::AccelerationStructureKHR,
    kind: vk::AccelerationStructureTypeKHR,
    geometry: vk::AccelerationStructureGeometryKHR<'static>,
    primitives: u32,
    scratch: u64,
}

/// One bottom-level acceleration structure over a triangle list and a top level holding one
/// instance of it (identity transform, mask 0xff), both preferring fast traces. Created empty:
/// [`Recorder::build_structures`] records their builds. Owns their buffers (vertices, instance,
/// storage and scratch); dropping it releases the structures, then the buffers (the GPU must be
/// done with them).
pub struct AccelerationStructures {
    loader: ash::khr::acceleration_structure::Device,
    structures: Vec<vk::AccelerationStructureKHR>,
    /// Dropped after the structures (fields drop after `drop`'s body).
    buffers: Vec<Buffer>,
    levels: Vec<Level>,
    tlas_address: u64,
    _owner: Arc<Owner>,
}

impl Drop for AccelerationStructures {
    fn drop(&mut self) {
        for s in self.structures.drain(..) {
            // SAFETY: created by this loader; the owner guarantees the GPU no longer uses it.
            unsafe { self.loader.destroy_acceleration_structure(s, None) };
        }
    }
}

impl std::fmt::Debug for AccelerationStructures {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AccelerationStructures").field("buffers", &self.buffers.len()).finish()
    }
}

impl AccelerationStructures {
    /// Creates the structures for `corners` (three per triangle, unindexed: primitive indices
    /// are triangle indices in this order) with their buffers; on failure everything made so far
    /// is released.
    pub fn new(gpu: &Gpu, corners: &[[f32; 3]]) -> PlayResult<AccelerationStructures> {
        if corners.is_empty() {
            return Err(PlayError::new(Exit::Gpu, "an acceleration structure needs at least one triangle"));
        }
        let mut s = AccelerationStructures {
            loader: ash::khr::acceleration_structure::Device::new(&gpu.instance, &gpu.device),
            structures: Vec::new(),
            buffers: Vec::new(),
            levels: Vec::new(),
            tlas_address: 0,
            _owner: gpu.owner(),
        };
        s.create(gpu, corners)?;
        Ok(s)
    }

    /// The top level's device address (what shaders trace against).
    pub fn tlas_address(&self) -> u64 {
        self.tlas_address
    }

    fn create(&mut self, gpu: &Gpu, corners: &[[f32; 3]]) -> PlayResult {
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
        let blas_address =
            self.structure(gpu, vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, blas_geometry, triangles)?;
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
        self.tlas_address =
            self.structure(gpu, vk::AccelerationStructureTypeKHR::TOP_LEVEL, tlas_geometry, 1)?;
        Ok(())
    }

    /// A host-visible buffer holding `bytes` (kept for release even when writing fails).
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

    fn build_info<'a>(
        kind: vk::AccelerationStructureTypeKHR,
        geometries: &'a [vk::AccelerationStructureGeometryKHR<'static>],
    ) -> vk::AccelerationStructureBuildGeometryInfoKHR<'a> {
        vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(kind)
            .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(geometries)
    }

    /// Creates one structure of `kind` sized for `geometry` × `primitives` with its storage and
    /// scratch buffers, records it as the next level to build, and returns its device address.
    fn structure(
        &mut self,
        gpu: &Gpu,
        kind: vk::AccelerationStructureTypeKHR,
        geometry: vk::AccelerationStructureGeometryKHR<'static>,
        primitives: u32,
    ) -> PlayResult<u64> {
        let geometries = [geometry];
        let info = Self::build_info(kind, &geometries);
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        // SAFETY: `info` describes one geometry with `primitives` primitives; `sizes` is written.
        unsafe {
            self.loader.get_acceleration_structure_build_sizes(
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
        // SAFETY: the storage buffer is at least the structure's size; released on drop.
        let handle = unsafe { self.loader.create_acceleration_structure(&create, None) }
            .map_err(|e| vk_err("creating an acceleration structure", e))?;
        self.structures.push(handle);
        let scratch = self.device_buffer(
            gpu,
            "acceleration structure scratch",
            sizes.build_scratch_size + SCRATCH_ALIGNMENT,
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        // SAFETY: `handle` is a live structure.
        let address = unsafe {
            self.loader.get_acceleration_structure_device_address(
                &vk::AccelerationStructureDeviceAddressInfoKHR::default().acceleration_structure(handle),
            )
        };
        self.levels.push(Level {
            handle,
            kind,
            geometry,
            primitives,
            scratch: self.buffers[scratch].address(gpu).next_multiple_of(SCRATCH_ALIGNMENT),
        });
        Ok(address)
    }
}

impl Recorder<'_> {
    /// Records the builds of `s`, bottom level first, each followed by a barrier that makes it
    /// visible to later builds (the top level reads the bottom level) and to ray-tracing shaders.
    pub fn build_structures(&self, s: &AccelerationStructures) {
        for level in &s.levels {
            let geometries = [level.geometry];
            let info = AccelerationStructures::build_info(level.kind, &geometries)
                .dst_acceleration_structure(level.handle)
                .scratch_data(vk::DeviceOrHostAddressKHR { device_address: level.scratch });
            let range =
                [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(level.primitives)];
            // SAFETY: the structure, its inputs and its scratch live as long as `s`.
            unsafe { s.loader.cmd_build_acceleration_structures(self.cmd, &[info], &[&range[..]]) };
            self.memory_barrier(
                vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR,
                vk::AccessFlags2::ACCELERATION_STRUCTURE_WRITE_KHR,
                vk::PipelineStageFlags2::ACCELERATION_STRUCTURE_BUILD_KHR
                    | vk::PipelineStageFlags2::RAY_TRACING_SHADER_KHR,
                vk::AccessFlags2::ACCELERATION_STRUCTURE_READ_KHR,
            );
        }
    }

    /// Binds `p`, pushes `push` to its ray-generation stage and launches `count` × 1 × 1 rays;
    /// returns the stage the shaders run in (for barriers on what they write).
    pub fn trace_rays(&self, p: &RayTracingPipeline, push: &[u8], count: u32) -> vk::PipelineStageFlags2 {
        // SAFETY: the pipeline, its layout and its binding table live as long as `p`.
        unsafe {
            let (raw, layout) = (p.pipeline.raw, p.pipeline.layout);
            self.gpu.device.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::RAY_TRACING_KHR, raw);
            self.gpu.device.cmd_push_constants(self.cmd, layout, vk::ShaderStageFlags::RAYGEN_KHR, 0, push);
            p.loader.cmd_trace_rays(
                self.cmd,
                &p.regions[0],
                &p.regions[1],
                &p.regions[2],
                &vk::StridedDeviceAddressRegionKHR::default(),
                count,
                1,
                1,
            );
        }
        vk::PipelineStageFlags2::RAY_TRACING_SHADER_KHR
    }
}

/// The SPIR-V of a ray-tracing pipeline's three shaders (entry points `main`).
#[derive(Debug, Clone, Copy)]
pub struct RayTracingShaders<'a> {
    /// Ray generation.
    pub raygen: &'a [u8],
    /// Miss.
    pub miss: &'a [u8],
    /// Closest hit of the triangle hit group.
    pub closest_hit: &'a [u8],
}

/// A ray-tracing pipeline of three groups (ray generation, miss, a triangle hit group with a
/// closest-hit shader), recursion depth 1, push constants for ray generation only, no descriptor
/// sets; with its shader binding table: one record per group, each at the base alignment.
/// Dropping it releases pipeline, layout and table (the GPU must be done with them).
pub struct RayTracingPipeline {
    loader: ash::khr::ray_tracing_pipeline::Device,
    pipeline: Pipeline,
    table: Option<Buffer>,
    regions: [vk::StridedDeviceAddressRegionKHR; 3],
}

impl std::fmt::Debug for RayTracingPipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RayTracingPipeline").finish()
    }
}

impl RayTracingPipeline {
    /// Usage the buffers its shaders reach by device address need.
    pub const BUFFER_USAGE: vk::BufferUsageFlags = ADDRESS;

    /// The pipeline for `shaders` with `push_bytes` of push constants; on failure everything
    /// made so far is released.
    pub fn new(gpu: &Gpu, shaders: &RayTracingShaders, push_bytes: u32) -> PlayResult<RayTracingPipeline> {
        let mut p = RayTracingPipeline {
            loader: ash::khr::ray_tracing_pipeline::Device::new(&gpu.instance, &gpu.device),
            pipeline: Pipeline::none(gpu),
            table: None,
            regions: [vk::StridedDeviceAddressRegionKHR::default(); 3],
        };
        p.create(gpu, shaders, push_bytes)?;
        Ok(p)
    }

    fn create(&mut self, gpu: &Gpu, shaders: &RayTracingShaders, push_bytes: u32) -> PlayResult {
        let pushes =
            [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::RAYGEN_KHR).size(push_bytes)];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default();
        if push_bytes > 0 {
            layout_info = layout_info.push_constant_ranges(&pushes);
        }
        // SAFETY: `layout_info` and its ranges live until the call returns; released on drop.
        self.pipeline.layout = unsafe { gpu.device.create_pipeline_layout(&layout_info, None) }
            .map_err(|e| vk_err("creating the ray-tracing pipeline layout", e))?;
        // Released when this returns, once the pipeline is created.
        let modules = [
            shader_module(gpu, shaders.raygen)?,
            shader_module(gpu, shaders.miss)?,
            shader_module(gpu, shaders.closest_hit)?,
        ];
        let main = c"main";
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::RAYGEN_KHR)
                .module(modules[0].raw)
                .name(main),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::MISS_KHR)
                .module(modules[1].raw)
                .name(main),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::CLOSEST_HIT_KHR)
                .module(modules[2].raw)
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
            .layout(self.pipeline.layout);
        // SAFETY: `info`, its stages and groups live until the call returns.
        let created = unsafe {
            self.loader.create_ray_tracing_pipelines(
                vk::DeferredOperationKHR::null(),
                gpu.pipeline_cache,
                &[info],
                None,
            )
        };
        self.pipeline.raw = match created {
            Ok(p) => p[0],
            Err((_, e)) => return Err(vk_err("creating the ray-tracing pipeline", e)),
        };
        self.binding_table(gpu)
    }

    /// Shader binding table: raygen, miss and hit records, each at the base alignment.
    fn binding_table(&mut self, gpu: &Gpu) -> PlayResult {
        let mut props = vk::PhysicalDeviceRayTracingPipelinePropertiesKHR::default();
        let mut p2 = vk::PhysicalDeviceProperties2::default().push_next(&mut props);
        // SAFETY: `p2` and its chain are valid for writing.
        unsafe { gpu.instance.get_physical_device_properties2(gpu.physical, &mut p2) };
        let handle = props.shader_group_handle_size as usize;
        let stride = (handle as u64).next_multiple_of(props.shader_group_handle_alignment.max(1) as u64);
        let base = props.shader_group_base_alignment.max(1) as u64;
        // SAFETY: the pipeline has three groups.
        let handles =
            unsafe { self.loader.get_ray_tracing_shader_group_handles(self.pipeline.raw, 0, 3, handle * 3) }
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
        self.table = Some(b);
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
}
