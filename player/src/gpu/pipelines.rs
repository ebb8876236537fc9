//! Shader modules, descriptor set layouts (each with its own pool), and compute and graphics
//! pipelines built through the device's pipeline cache. Each releases what it owns when dropped.

use std::sync::Arc;

use ash::vk;

use super::{Buffer, Gpu, Owner};
use crate::error::{Exit, PlayError, PlayResult, vk as vk_err};

/// A shader module, released when dropped (once the pipelines made from it are created).
pub(super) struct ShaderModule {
    /// Handle.
    pub(super) raw: vk::ShaderModule,
    owner: Arc<Owner>,
}

impl Drop for ShaderModule {
    fn drop(&mut self) {
        // SAFETY: made on this device; a module is needed only while pipelines are created.
        unsafe { self.owner.device.destroy_shader_module(self.raw, None) };
    }
}

/// A shader module from SPIR-V bytes.
pub(super) fn shader_module(gpu: &Gpu, spirv: &[u8]) -> PlayResult<ShaderModule> {
    let words = ash::util::read_spv(&mut std::io::Cursor::new(spirv))
        .map_err(|e| PlayError::new(Exit::Gpu, format!("invalid SPIR-V: {e}")))?;
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    let raw = unsafe { gpu.device.create_shader_module(&info, None) }
        .map_err(|e| vk_err("creating a shader module", e))?;
    Ok(ShaderModule { raw, owner: gpu.owner() })
}

/// Kind of a descriptor binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BindingKind {
    /// Uniform buffer.
    Uniform,
    /// Storage buffer.
    Storage,
    /// Combined image sampler.
    Sampled,
    /// Storage image.
    StorageImage,
}

impl BindingKind {
    fn vk(self) -> vk::DescriptorType {
        match self {
            BindingKind::Uniform => vk::DescriptorType::UNIFORM_BUFFER,
            BindingKind::Storage => vk::DescriptorType::STORAGE_BUFFER,
            BindingKind::Sampled => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
        }
    }
}

/// One binding of a set: kind and array size.
#[derive(Debug, Clone, Copy)]
pub struct Binding {
    /// Kind.
    pub kind: BindingKind,
    /// Array size.
    pub count: u32,
}

impl Binding {
    /// One descriptor of `kind`.
    pub const fn one(kind: BindingKind) -> Binding {
        Binding { kind, count: 1 }
    }
}

/// A descriptor set layout and the pools its sets come from (grown `chunk` sets at a time);
/// dropping it releases the pools, and every set from them, and the layout.
#[derive(Debug)]
pub struct SetLayout {
    /// Layout handle.
    pub raw: vk::DescriptorSetLayout,
    pools: Vec<(vk::DescriptorPool, u32)>,
    chunk: u32,
    bindings: Vec<Binding>,
    owner: Arc<Owner>,
}

impl Drop for SetLayout {
    fn drop(&mut self) {
        // SAFETY: made on this device; its owner guarantees no submitted work uses the sets.
        unsafe {
            for (pool, _) in self.pools.drain(..) {
                self.owner.device.destroy_descriptor_pool(pool, None);
            }
            self.owner.device.destroy_descriptor_set_layout(self.raw, None);
        }
    }
}

/// One descriptor write.
#[derive(Debug)]
pub enum Write<'a> {
    /// A whole buffer at a binding.
    Buffer(u32, &'a Buffer),
    /// Sampled images (view, sampler) at a binding, from array element 0; layout
    /// SHADER_READ_ONLY_OPTIMAL.
    Sampled(u32, Vec<(vk::ImageView, vk::Sampler)>),
    /// A storage image (GENERAL layout).
    StorageImage(u32, vk::ImageView),
    /// Storage images at a binding, from array element 0 (GENERAL layout).
    StorageImages(u32, Vec<vk::ImageView>),
}

impl SetLayout {
    /// A layout visible to every stage.
    pub fn new(gpu: &Gpu, bindings: &[Binding], chunk: u32) -> PlayResult<SetLayout> {
        let vk_bindings: Vec<vk::DescriptorSetLayoutBinding> = bindings
            .iter()
            .enumerate()
            .map(|(i, b)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(b.kind.vk())
                    .descriptor_count(b.count)
                    .stage_flags(vk::ShaderStageFlags::ALL)
            })
            .collect();
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&vk_bindings);
        let raw = unsafe { gpu.device.create_descriptor_set_layout(&info, None) }
            .map_err(|e| vk_err("creating a descriptor set layout", e))?;
        Ok(SetLayout {
            raw,
            pools: Vec::new(),
            chunk: chunk.max(1),
            bindings: bindings.to_vec(),
            owner: gpu.owner(),
        })
    }

    /// A new set, from a new pool when the last one is full.
    pub fn allocate(&mut self, gpu: &Gpu) -> PlayResult<vk::DescriptorSet> {
        if self.pools.last().is_none_or(|p| p.1 >= self.chunk) {
            let sizes: Vec<vk::DescriptorPoolSize> = self
                .bindings
                .iter()
                .map(|b| vk::DescriptorPoolSize { ty: b.kind.vk(), descriptor_count: b.count * self.chunk })
                .collect();
            let pool_info = vk::DescriptorPoolCreateInfo::default().max_sets(self.chunk).pool_sizes(&sizes);
            let pool = unsafe { gpu.device.create_descriptor_pool(&pool_info, None) }
                .map_err(|e| vk_err("creating a descriptor pool", e))?;
            self.pools.push((pool, 0));
        }
        let Some(last) = self.pools.last_mut() else { unreachable!("a pool was just ensured") };
        let layouts = [self.raw];
        let info = vk::DescriptorSetAllocateInfo::default().descriptor_pool(last.0).set_layouts(&layouts);
        let sets = unsafe { gpu.device.allocate_descriptor_sets(&info) }
            .map_err(|e| vk_err("allocating a descriptor set", e))?;
        last.1 += 1;
        Ok(sets[0])
    }

    /// Writes descriptors of `set`.
    pub fn write(&self, gpu: &Gpu, set: vk::DescriptorSet, writes: &[Write]) {
        let mut buffer_infos: Vec<[vk::DescriptorBufferInfo; 1]> = Vec::new();
        let mut image_infos: Vec<Vec<vk::DescriptorImageInfo>> = Vec::new();
        for w in writes {
            match w {
                Write::Buffer(_, b) => buffer_infos.push([vk::DescriptorBufferInfo {
                    buffer: b.raw,
                    offset: 0,
                    range: vk::WHOLE_SIZE,
                }]),
                Write::Sampled(_, images) => image_infos.push(
                    images
                        .iter()
                        .map(|&(view, sampler)| vk::DescriptorImageInfo {
                            sampler,
                            image_view: view,
                            image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                        })
                        .collect(),
                ),
                Write::StorageImage(_, view) => image_infos.push(vec![vk::DescriptorImageInfo {
                    sampler: vk::Sampler::null(),
                    image_view: *view,
                    image_layout: vk::ImageLayout::GENERAL,
                }]),
                Write::StorageImages(_, views) => image_infos.push(
                    views
                        .iter()
                        .map(|&image_view| vk::DescriptorImageInfo {
                            sampler: vk::Sampler::null(),
                            image_view,
                            image_layout: vk::ImageLayout::GENERAL,
                        })
                        .collect(),
                ),
            }
        }
        let (mut bi, mut ii) = (0, 0);
        let vk_writes: Vec<vk::WriteDescriptorSet> = writes
            .iter()
            .map(|w| {
                let (binding, base) = match w {
                    Write::Buffer(b, _)
                    | Write::Sampled(b, _)
                    | Write::StorageImage(b, _)
                    | Write::StorageImages(b, _) => (*b, vk::WriteDescriptorSet::default().dst_set(set)),
                };
                let ty = self.bindings[binding as usize].kind.vk();
                let base = base.dst_binding(binding).descriptor_type(ty);
                match w {
                    Write::Buffer(..) => {
                        bi += 1;
                        base.buffer_info(&buffer_infos[bi - 1])
                    }
                    _ => {
                        ii += 1;
                        base.image_info(&image_infos[ii - 1])
                    }
                }
            })
            .collect();
        unsafe { gpu.device.update_descriptor_sets(&vk_writes, &[]) };
    }
}

/// A pipeline and its layout, released when dropped: what [`ComputePipeline`],
/// [`GraphicsPipeline`] and the ray-tracing pipeline hold.
#[derive(Debug)]
pub(super) struct Pipeline {
    /// Pipeline (null until created).
    pub(super) raw: vk::Pipeline,
    /// Layout (null until created).
    pub(super) layout: vk::PipelineLayout,
    owner: Arc<Owner>,
}

impl Pipeline {
    /// Neither made yet: null handles, filled in by the caller.
    pub(super) fn none(gpu: &Gpu) -> Pipeline {
        Pipeline { raw: vk::Pipeline::null(), layout: vk::PipelineLayout::null(), owner: gpu.owner() }
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        // SAFETY: made on this device (null handles are ignored); its owner guarantees no
        // submitted work uses it any more.
        unsafe {
            self.owner.device.destroy_pipeline(self.raw, None);
            self.owner.device.destroy_pipeline_layout(self.layout, None);
        }
    }
}

/// A pipeline layout for `sets` and `push_bytes` of push constants, with no pipeline yet.
fn layout_only(gpu: &Gpu, sets: &[&SetLayout], push_bytes: u32) -> PlayResult<Pipeline> {
    let mut p = Pipeline::none(gpu);
    p.layout = pipeline_layout(gpu, sets, push_bytes)?;
    Ok(p)
}

fn pipeline_layout(gpu: &Gpu, sets: &[&SetLayout], push_bytes: u32) -> PlayResult<vk::PipelineLayout> {
    let layouts: Vec<vk::DescriptorSetLayout> = sets.iter().map(|s| s.raw).collect();
    let ranges =
        [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::ALL, offset: 0, size: push_bytes }];
    let mut info = vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts);
    if push_bytes > 0 {
        info = info.push_constant_ranges(&ranges);
    }
    unsafe { gpu.device.create_pipeline_layout(&info, None) }
        .map_err(|e| vk_err("creating a pipeline layout", e))
}

/// A compute pipeline and its layout, released when dropped.
#[derive(Debug)]
pub struct ComputePipeline {
    /// Pipeline.
    pub raw: vk::Pipeline,
    /// Layout.
    pub layout: vk::PipelineLayout,
    _owned: Pipeline,
}

impl ComputePipeline {
    /// A compute pipeline from SPIR-V with entry point `main`, its specialization constants at
    /// their defaults.
    pub fn new(gpu: &Gpu, spirv: &[u8], sets: &[&SetLayout], push_bytes: u32) -> PlayResult<ComputePipeline> {
        Self::specialized(gpu, spirv, sets, push_bytes, &[])
    }

    /// A compute pipeline whose specialization constant `constant_id = i` is `constants[i]`
    /// (32 bits each; a bool is 0 or 1). The driver folds them before it compiles, and the
    /// pipeline cache keys on them. Ids the shader does not declare are ignored.
    pub fn specialized(
        gpu: &Gpu,
        spirv: &[u8],
        sets: &[&SetLayout],
        push_bytes: u32,
        constants: &[u32],
    ) -> PlayResult<ComputePipeline> {
        let module = shader_module(gpu, spirv)?;
        let mut owned = layout_only(gpu, sets, push_bytes)?;
        let entries: Vec<vk::SpecializationMapEntry> = (0..constants.len() as u32)
            .map(|i| vk::SpecializationMapEntry { constant_id: i, offset: 4 * i, size: 4 })
            .collect();
        let spec =
            vk::SpecializationInfo::default().map_entries(&entries).data(bytemuck::cast_slice(constants));
        let mut stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module.raw)
            .name(c"main");
        if !constants.is_empty() {
            stage = stage.specialization_info(&spec);
        }
        let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(owned.layout);
        let result = unsafe { gpu.device.create_compute_pipelines(gpu.pipeline_cache, &[info], None) };
        owned.raw = result.map_err(|(_, e)| vk_err("creating a compute pipeline", e))?[0];
        Ok(ComputePipeline { raw: owned.raw, layout: owned.layout, _owned: owned })
    }
}

/// What a graphics pipeline draws.
#[derive(Debug)]
pub struct GraphicsDesc<'a> {
    /// Vertex shader SPIR-V.
    pub vertex: &'a [u8],
    /// Fragment shader SPIR-V.
    pub fragment: &'a [u8],
    /// Vertex buffer strides, one binding each.
    pub vertex_strides: &'a [u32],
    /// (location, binding, format, offset) of each vertex attribute.
    pub attributes: &'a [(u32, u32, vk::Format, u32)],
    /// Colour attachment formats.
    pub colors: &'a [vk::Format],
    /// Depth attachment format.
    pub depth: vk::Format,
    /// Descriptor sets.
    pub sets: &'a [&'a SetLayout],
    /// Push constant bytes.
    pub push_bytes: u32,
    /// Cull back (clockwise) faces in hardware; otherwise nothing is culled and the fragment
    /// shader decides facing.
    pub cull_back: bool,
    /// How its fragments land in the targets.
    pub landing: Landing,
}

/// How a graphics pipeline's fragments land in its targets. (One way for every target: each
/// target its own would need the `independentBlend` feature.)
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Landing {
    /// Depth-tested (the nearest wins, reversed Z) and written.
    Nearest,
    /// Added to what the targets hold (one-plus-one blending), without depth test or write:
    /// every fragment counts, in any order.
    Summed,
}

/// A graphics pipeline for dynamic rendering and its layout, released when dropped.
#[derive(Debug)]
pub struct GraphicsPipeline {
    /// Pipeline.
    pub raw: vk::Pipeline,
    /// Layout.
    pub layout: vk::PipelineLayout,
    _owned: Pipeline,
}

impl GraphicsPipeline {
    /// A triangle-list pipeline with a reversed-Z depth test, optional back-face culling, dynamic
    /// viewport and scissor.
    pub fn new(gpu: &Gpu, d: &GraphicsDesc) -> PlayResult<GraphicsPipeline> {
        let vs = shader_module(gpu, d.vertex)?;
        let fs = shader_module(gpu, d.fragment)?;
        let mut owned = layout_only(gpu, d.sets, d.push_bytes)?;
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vs.raw)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fs.raw)
                .name(c"main"),
        ];
        let bindings: Vec<vk::VertexInputBindingDescription> = d
            .vertex_strides
            .iter()
            .enumerate()
            .map(|(i, &s)| vk::VertexInputBindingDescription {
                binding: i as u32,
                stride: s,
                input_rate: vk::VertexInputRate::VERTEX,
            })
            .collect();
        let attributes: Vec<vk::VertexInputAttributeDescription> = d
            .attributes
            .iter()
            .map(|&(location, binding, format, offset)| vk::VertexInputAttributeDescription {
                location,
                binding,
                format,
                offset,
            })
            .collect();
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&bindings)
            .vertex_attribute_descriptions(&attributes);
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(if d.cull_back { vk::CullModeFlags::BACK } else { vk::CullModeFlags::NONE })
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let nearest = d.landing == Landing::Nearest;
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(nearest)
            .depth_write_enable(nearest)
            .depth_compare_op(vk::CompareOp::GREATER_OR_EQUAL); // reversed Z
        let written =
            vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA);
        let attachment = match d.landing {
            Landing::Nearest => written,
            Landing::Summed => written
                .blend_enable(true)
                .src_color_blend_factor(vk::BlendFactor::ONE)
                .dst_color_blend_factor(vk::BlendFactor::ONE)
                .color_blend_op(vk::BlendOp::ADD)
                .src_alpha_blend_factor(vk::BlendFactor::ONE)
                .dst_alpha_blend_factor(vk::BlendFactor::ONE)
                .alpha_blend_op(vk::BlendOp::ADD),
        };
        let blend_attachments = vec![attachment; d.colors.len()];
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(d.colors)
            .depth_attachment_format(d.depth);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(owned.layout)
            .push_next(&mut rendering);
        let result = unsafe { gpu.device.create_graphics_pipelines(gpu.pipeline_cache, &[info], None) };
        owned.raw = result.map_err(|(_, e)| vk_err("creating a graphics pipeline", e))?[0];
        Ok(GraphicsPipeline { raw: owned.raw, layout: owned.layout, _owned: owned })
    }
}
