//! Command recording and submission, barriers, timestamps, semaphores.

use std::sync::Arc;

use ash::vk;

use super::{Buffer, ComputePipeline, Gpu, GraphicsPipeline, Image, Owner};
use crate::error::{PlayResult, vk as vk_err};

/// A command pool with one primary command buffer and a fence, for one queue family. Dropping
/// it waits for its last submission, then releases pool, command buffer and fence.
#[derive(Debug)]
pub struct CommandPool {
    pool: vk::CommandPool,
    /// The command buffer.
    pub cmd: vk::CommandBuffer,
    /// Signalled when the last submission finished (or when nothing was submitted): it is reset
    /// only just before a submission, and replaced by a signalled one if that submission fails,
    /// so that no wait can hang on work that never reached the queue.
    fence: std::cell::Cell<vk::Fence>,
    family: u32,
    owner: Arc<Owner>,
}

impl Drop for CommandPool {
    fn drop(&mut self) {
        let device = &self.owner.device;
        // SAFETY: made on this device (a null fence is ignored); once the fence is signalled the
        // command buffer is not pending, and freeing the pool frees it.
        unsafe {
            let fence = self.fence.get();
            if fence != vk::Fence::null() {
                let _ = device.wait_for_fences(&[fence], true, u64::MAX);
            }
            device.destroy_fence(fence, None);
            device.destroy_command_pool(self.pool, None);
        }
    }
}

impl CommandPool {
    /// A pool for `family`.
    pub fn new(gpu: &Gpu, family: u32) -> PlayResult<CommandPool> {
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let pool = unsafe { gpu.device.create_command_pool(&info, None) }
            .map_err(|e| vk_err("creating a command pool", e))?;
        // Released on any error below.
        let mut made = CommandPool {
            pool,
            cmd: vk::CommandBuffer::null(),
            fence: std::cell::Cell::new(vk::Fence::null()),
            family,
            owner: gpu.owner(),
        };
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        made.cmd = unsafe { gpu.device.allocate_command_buffers(&alloc) }
            .map_err(|e| vk_err("allocating a command buffer", e))?[0];
        let fence = unsafe {
            gpu.device
                .create_fence(&vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED), None)
        }
        .map_err(|e| vk_err("creating a fence", e))?;
        made.fence.set(fence);
        Ok(made)
    }

    /// Waits for the previous submission, then starts recording.
    pub fn begin<'a>(&self, gpu: &'a Gpu) -> PlayResult<Recorder<'a>> {
        self.wait(gpu)?;
        unsafe {
            gpu.device
                .reset_command_buffer(self.cmd, vk::CommandBufferResetFlags::empty())
                .map_err(|e| vk_err("resetting a command buffer", e))?;
            gpu.device
                .begin_command_buffer(
                    self.cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .map_err(|e| vk_err("beginning a command buffer", e))?;
        }
        Ok(Recorder { gpu, cmd: self.cmd })
    }

    /// Ends recording and submits to the queue of this pool's family, waiting on and signalling
    /// the given semaphores.
    pub fn submit(&self, gpu: &Gpu, wait: &[SemaphoreOp], signal: &[SemaphoreOp]) -> PlayResult {
        unsafe { gpu.device.end_command_buffer(self.cmd) }
            .map_err(|e| vk_err("ending a command buffer", e))?;
        let queue = if gpu.transfer.is_some_and(|t| t.0 == self.family) {
            gpu.transfer.map(|t| t.1).unwrap_or(gpu.queue)
        } else {
            gpu.queue
        };
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(self.cmd)];
        let info_of = |op: &SemaphoreOp| {
            vk::SemaphoreSubmitInfo::default().semaphore(op.semaphore).value(op.value).stage_mask(op.stage)
        };
        let waits: Vec<vk::SemaphoreSubmitInfo> = wait.iter().map(info_of).collect();
        let signals: Vec<vk::SemaphoreSubmitInfo> = signal.iter().map(info_of).collect();
        let info = vk::SubmitInfo2::default()
            .command_buffer_infos(&cmds)
            .wait_semaphore_infos(&waits)
            .signal_semaphore_infos(&signals);
        let fence = self.fence.get();
        unsafe { gpu.device.reset_fences(&[fence]) }.map_err(|e| vk_err("resetting a fence", e))?;
        let submitted = unsafe { gpu.device.queue_submit2(queue, &[info], fence) };
        if let Err(e) = submitted {
            let signalled = vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED);
            if let Ok(replacement) = unsafe { gpu.device.create_fence(&signalled, None) } {
                unsafe { gpu.device.destroy_fence(fence, None) };
                self.fence.set(replacement);
            }
            return Err(vk_err("submitting commands", e));
        }
        Ok(())
    }

    /// Waits until the last submission finished.
    pub fn wait(&self, gpu: &Gpu) -> PlayResult {
        unsafe { gpu.device.wait_for_fences(&[self.fence.get()], true, u64::MAX) }
            .map_err(|e| vk_err("waiting for the GPU", e))
    }

    /// Whether the last submission finished.
    pub fn done(&self, gpu: &Gpu) -> bool {
        unsafe { gpu.device.get_fence_status(self.fence.get()) }.unwrap_or(false)
    }
}

/// A semaphore, released when dropped (no submitted work may still wait on or signal it).
#[derive(Debug)]
pub struct Semaphore {
    /// Handle.
    pub raw: vk::Semaphore,
    pub(super) owner: Arc<Owner>,
}

impl Drop for Semaphore {
    fn drop(&mut self) {
        // SAFETY: made on this device; its owner guarantees no submitted work uses it any more.
        unsafe { self.owner.device.destroy_semaphore(self.raw, None) };
    }
}

/// A semaphore wait or signal of a submission: `value` is the timeline value (ignored for binary
/// semaphores), `stage` the stages that wait or that must finish before the signal.
#[derive(Debug, Clone, Copy)]
pub struct SemaphoreOp {
    /// The semaphore.
    pub semaphore: vk::Semaphore,
    /// Timeline value.
    pub value: u64,
    /// Stage mask.
    pub stage: vk::PipelineStageFlags2,
}

impl SemaphoreOp {
    /// A binary semaphore at `stage`.
    pub fn binary(semaphore: vk::Semaphore, stage: vk::PipelineStageFlags2) -> Self {
        SemaphoreOp { semaphore, value: 0, stage }
    }

    /// Timeline `semaphore` at `value`, all stages.
    pub fn timeline(semaphore: vk::Semaphore, value: u64) -> Self {
        SemaphoreOp { semaphore, value, stage: vk::PipelineStageFlags2::ALL_COMMANDS }
    }
}

/// A band of rows of one mip level and layer of an image.
#[derive(Debug, Clone, Copy)]
pub struct ImageRows {
    /// Mip level.
    pub mip: u32,
    /// Array layer (cube face).
    pub layer: u32,
    /// First row.
    pub y: u32,
    /// Row width in texels (the level's width).
    pub width: u32,
    /// Number of rows.
    pub rows: u32,
}

/// A command buffer being recorded.
#[derive(Debug)]
pub struct Recorder<'a> {
    pub(super) gpu: &'a Gpu,
    /// The command buffer.
    pub cmd: vk::CommandBuffer,
}

/// Where and how an image is used, for barriers.
#[derive(Debug, Clone, Copy)]
pub struct Use {
    /// Layout.
    pub layout: vk::ImageLayout,
    /// Pipeline stages.
    pub stage: vk::PipelineStageFlags2,
    /// Access.
    pub access: vk::AccessFlags2,
}

impl Use {
    /// Contents discarded. The barrier still waits for all earlier commands, so reusing a target
    /// that the previous frame read is ordered after those reads.
    pub const DISCARD: Use = Use {
        layout: vk::ImageLayout::UNDEFINED,
        stage: vk::PipelineStageFlags2::ALL_COMMANDS,
        access: vk::AccessFlags2::NONE,
    };
    /// Uploaded and ready for sampling; the end state of an upload on a transfer queue (which
    /// cannot name shader stages). The semaphore the frame waits on makes the writes visible.
    pub const UPLOADED: Use = Use {
        layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        stage: vk::PipelineStageFlags2::ALL_COMMANDS,
        access: vk::AccessFlags2::NONE,
    };
    /// Transfer destination.
    pub const TRANSFER_DST: Use = Use {
        layout: vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        stage: vk::PipelineStageFlags2::TRANSFER,
        access: vk::AccessFlags2::TRANSFER_WRITE,
    };
    /// Transfer source.
    pub const TRANSFER_SRC: Use = Use {
        layout: vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        stage: vk::PipelineStageFlags2::TRANSFER,
        access: vk::AccessFlags2::TRANSFER_READ,
    };
    /// Sampled by any shader.
    pub const SAMPLED: Use = Use {
        layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        stage: vk::PipelineStageFlags2::ALL_COMMANDS,
        access: vk::AccessFlags2::SHADER_SAMPLED_READ,
    };
    /// Written as a colour attachment.
    pub const COLOR: Use = Use {
        layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        access: vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
    };
    /// Written as the depth attachment.
    pub const DEPTH: Use = Use {
        layout: vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
        ),
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw(),
        ),
    };
    /// Read and written as a storage image by compute shaders.
    pub const STORAGE: Use = Use {
        layout: vk::ImageLayout::GENERAL,
        stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::SHADER_STORAGE_READ.as_raw() | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
        ),
    };
    /// Presented to a swapchain.
    pub const PRESENT: Use = Use {
        layout: vk::ImageLayout::PRESENT_SRC_KHR,
        stage: vk::PipelineStageFlags2::BOTTOM_OF_PIPE,
        access: vk::AccessFlags2::NONE,
    };
}

impl<'a> Recorder<'a> {
    /// A handle to a command buffer already begun by [`CommandPool::begin`], to record more.
    pub fn continuing(gpu: &'a Gpu, cmd: vk::CommandBuffer) -> Recorder<'a> {
        Recorder { gpu, cmd }
    }

    /// Transitions `image` (handle and range) from one use to another.
    pub fn transition_raw(&self, image: vk::Image, range: vk::ImageSubresourceRange, from: Use, to: Use) {
        let barrier = vk::ImageMemoryBarrier2::default()
            .image(image)
            .subresource_range(range)
            .old_layout(from.layout)
            .new_layout(to.layout)
            .src_stage_mask(from.stage)
            .src_access_mask(from.access)
            .dst_stage_mask(to.stage)
            .dst_access_mask(to.access);
        let barriers = [barrier];
        let dep = vk::DependencyInfo::default().image_memory_barriers(&barriers);
        unsafe { self.gpu.device.cmd_pipeline_barrier2(self.cmd, &dep) };
    }

    /// Transitions a whole image.
    pub fn transition(&self, image: &Image, from: Use, to: Use) {
        self.transition_raw(image.raw, image.range(), from, to);
    }

    /// Transitions whole images, in one barrier command (nothing when `list` is empty).
    pub fn transitions(&self, list: &[(&Image, Use, Use)]) {
        if list.is_empty() {
            return;
        }
        let barriers: Vec<vk::ImageMemoryBarrier2> = list
            .iter()
            .map(|(image, from, to)| {
                vk::ImageMemoryBarrier2::default()
                    .image(image.raw)
                    .subresource_range(image.range())
                    .old_layout(from.layout)
                    .new_layout(to.layout)
                    .src_stage_mask(from.stage)
                    .src_access_mask(from.access)
                    .dst_stage_mask(to.stage)
                    .dst_access_mask(to.access)
            })
            .collect();
        let dep = vk::DependencyInfo::default().image_memory_barriers(&barriers);
        unsafe { self.gpu.device.cmd_pipeline_barrier2(self.cmd, &dep) };
    }

    /// A global memory barrier.
    pub fn memory_barrier(
        &self,
        src_stage: vk::PipelineStageFlags2,
        src: vk::AccessFlags2,
        dst_stage: vk::PipelineStageFlags2,
        dst: vk::AccessFlags2,
    ) {
        let barriers = [vk::MemoryBarrier2::default()
            .src_stage_mask(src_stage)
            .src_access_mask(src)
            .dst_stage_mask(dst_stage)
            .dst_access_mask(dst)];
        let dep = vk::DependencyInfo::default().memory_barriers(&barriers);
        unsafe { self.gpu.device.cmd_pipeline_barrier2(self.cmd, &dep) };
    }

    /// Fills `size` bytes of `dst` from `offset` with a repeated u32.
    pub fn fill_buffer(&self, dst: &Buffer, offset: u64, size: u64, value: u32) {
        unsafe { self.gpu.device.cmd_fill_buffer(self.cmd, dst.raw, offset, size, value) };
    }

    /// Copies bytes between buffers.
    pub fn copy_buffer(&self, src: &Buffer, src_offset: u64, dst: &Buffer, dst_offset: u64, size: u64) {
        let region = [vk::BufferCopy { src_offset, dst_offset, size }];
        unsafe { self.gpu.device.cmd_copy_buffer(self.cmd, src.raw, dst.raw, &region) };
    }

    /// Copies tightly packed texels from a buffer into `rows` rows from row `y` of one mip level
    /// and layer of an image in TRANSFER_DST layout.
    pub fn copy_to_image(&self, src: &Buffer, offset: u64, image: &Image, at: ImageRows) {
        let region = [vk::BufferImageCopy {
            buffer_offset: offset,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: super::resources::aspect_of(image.desc.format),
                mip_level: at.mip,
                base_array_layer: at.layer,
                layer_count: 1,
            },
            image_offset: vk::Offset3D { x: 0, y: at.y as i32, z: 0 },
            image_extent: vk::Extent3D { width: at.width, height: at.rows, depth: 1 },
        }];
        unsafe {
            self.gpu.device.cmd_copy_buffer_to_image(
                self.cmd,
                src.raw,
                image.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
            )
        };
    }

    /// Copies mip 0 of an image (TRANSFER_SRC layout) into a buffer, tightly packed.
    pub fn copy_from_image(&self, image: &Image, dst: &Buffer) {
        let region = [vk::BufferImageCopy {
            buffer_offset: 0,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            },
            image_offset: vk::Offset3D::default(),
            image_extent: vk::Extent3D { width: image.desc.width, height: image.desc.height, depth: 1 },
        }];
        unsafe {
            self.gpu.device.cmd_copy_image_to_buffer(
                self.cmd,
                image.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                dst.raw,
                &region,
            )
        };
    }

    /// Blits `src` (TRANSFER_SRC) over the whole of `dst` (TRANSFER_DST), nearest filtering.
    pub fn blit(&self, src: &Image, dst: vk::Image, width: u32, height: u32) {
        let sub = vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        };
        let region = vk::ImageBlit2::default()
            .src_subresource(sub)
            .src_offsets([
                vk::Offset3D::default(),
                vk::Offset3D { x: src.desc.width as i32, y: src.desc.height as i32, z: 1 },
            ])
            .dst_subresource(sub)
            .dst_offsets([vk::Offset3D::default(), vk::Offset3D { x: width as i32, y: height as i32, z: 1 }]);
        let regions = [region];
        let info = vk::BlitImageInfo2::default()
            .src_image(src.raw)
            .src_image_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .dst_image(dst)
            .dst_image_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .regions(&regions)
            .filter(vk::Filter::NEAREST);
        unsafe { self.gpu.device.cmd_blit_image2(self.cmd, &info) };
    }

    /// Begins dynamic rendering into colour targets (cleared to zero when `clear_colors`, else
    /// left undefined where nothing is drawn) and a depth target (cleared to 0: reversed Z).
    pub fn begin_rendering(&self, colors: &[&Image], depth: &Image, clear_colors: bool) {
        self.begin_rendering_in(colors, Some(depth), clear_colors, None);
    }

    /// [`Recorder::begin_rendering`] with the depth target optional, and confined to `area`
    /// (the whole image without one): clears, rasterisation and stores stay inside it (what is
    /// outside is whatever the image's last layout transition left: undefined after one from
    /// UNDEFINED). At least one target must be given.
    pub fn begin_rendering_in(
        &self,
        colors: &[&Image],
        depth: Option<&Image>,
        clear_colors: bool,
        area: Option<vk::Rect2D>,
    ) {
        let color_infos: Vec<vk::RenderingAttachmentInfo> = colors
            .iter()
            .map(|c| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(c.view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(if clear_colors {
                        vk::AttachmentLoadOp::CLEAR
                    } else {
                        vk::AttachmentLoadOp::DONT_CARE
                    })
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } })
            })
            .collect();
        let depth_info = depth.map(|d| {
            vk::RenderingAttachmentInfo::default()
                .image_view(d.view)
                .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue { depth: 0.0, stencil: 0 },
                })
        });
        let size = depth
            .or(colors.first().copied())
            .map(|i| (i.desc.width, i.desc.height))
            .expect("dynamic rendering needs at least one target");
        let extent = vk::Extent2D { width: size.0, height: size.1 };
        let area = area.unwrap_or(vk::Rect2D { offset: vk::Offset2D::default(), extent });
        let mut info =
            vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&color_infos);
        if let Some(d) = &depth_info {
            info = info.depth_attachment(d);
        }
        unsafe {
            self.gpu.device.cmd_begin_rendering(self.cmd, &info);
            // A negative-height viewport makes clip-space y point up the image.
            let viewport = vk::Viewport {
                x: 0.0,
                y: extent.height as f32,
                width: extent.width as f32,
                height: -(extent.height as f32),
                min_depth: 0.0,
                max_depth: 1.0,
            };
            self.gpu.device.cmd_set_viewport(self.cmd, 0, &[viewport]);
            self.gpu.device.cmd_set_scissor(self.cmd, 0, &[area]);
        }
    }

    /// Ends dynamic rendering.
    pub fn end_rendering(&self) {
        unsafe { self.gpu.device.cmd_end_rendering(self.cmd) };
    }

    /// Binds a graphics pipeline and its descriptor sets from set 0.
    pub fn bind_graphics(&self, p: &GraphicsPipeline, sets: &[vk::DescriptorSet]) {
        unsafe {
            self.gpu.device.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::GRAPHICS, p.raw);
            if !sets.is_empty() {
                self.gpu.device.cmd_bind_descriptor_sets(
                    self.cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    p.layout,
                    0,
                    sets,
                    &[],
                );
            }
        }
    }

    /// Binds descriptor set `index` of a graphics pipeline.
    pub fn bind_graphics_set(&self, p: &GraphicsPipeline, index: u32, set: vk::DescriptorSet) {
        unsafe {
            self.gpu.device.cmd_bind_descriptor_sets(
                self.cmd,
                vk::PipelineBindPoint::GRAPHICS,
                p.layout,
                index,
                &[set],
                &[],
            )
        };
    }

    /// Pushes constants to a graphics pipeline.
    pub fn push_graphics(&self, p: &GraphicsPipeline, bytes: &[u8]) {
        unsafe {
            self.gpu.device.cmd_push_constants(self.cmd, p.layout, vk::ShaderStageFlags::ALL, 0, bytes)
        };
    }

    /// Binds vertex buffers from binding 0 and a u32 index buffer.
    pub fn bind_geometry(&self, vertices: &[&Buffer], indices: &Buffer) {
        let raws: Vec<vk::Buffer> = vertices.iter().map(|b| b.raw).collect();
        let offsets = vec![0u64; raws.len()];
        unsafe {
            self.gpu.device.cmd_bind_vertex_buffers(self.cmd, 0, &raws, &offsets);
            self.gpu.device.cmd_bind_index_buffer(self.cmd, indices.raw, 0, vk::IndexType::UINT32);
        }
    }

    /// Draws `count` indices from `first`.
    pub fn draw_indexed(&self, count: u32, first: u32) {
        // The first instance carries the first triangle (gl_InstanceIndex in the G-buffer pass).
        unsafe { self.gpu.device.cmd_draw_indexed(self.cmd, count, 1, first, 0, first / 3) };
    }

    /// Binds a compute pipeline with its sets and dispatches enough 8 × 8 groups for w × h.
    pub fn dispatch_2d(&self, p: &ComputePipeline, sets: &[vk::DescriptorSet], w: u32, h: u32) {
        unsafe {
            self.gpu.device.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::COMPUTE, p.raw);
            self.gpu.device.cmd_bind_descriptor_sets(
                self.cmd,
                vk::PipelineBindPoint::COMPUTE,
                p.layout,
                0,
                sets,
                &[],
            );
            self.gpu.device.cmd_dispatch(self.cmd, w.div_ceil(8), h.div_ceil(8), 1);
        }
    }

    /// Binds a compute pipeline, its sets and push constants, and dispatches `groups`.
    pub fn dispatch(&self, p: &ComputePipeline, sets: &[vk::DescriptorSet], push: &[u8], groups: [u32; 3]) {
        unsafe {
            self.gpu.device.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::COMPUTE, p.raw);
            self.gpu.device.cmd_bind_descriptor_sets(
                self.cmd,
                vk::PipelineBindPoint::COMPUTE,
                p.layout,
                0,
                sets,
                &[],
            );
            if !push.is_empty() {
                self.gpu.device.cmd_push_constants(self.cmd, p.layout, vk::ShaderStageFlags::ALL, 0, push);
            }
            self.gpu.device.cmd_dispatch(self.cmd, groups[0], groups[1], groups[2]);
        }
    }

    /// Resets a query range (before its timestamps are written).
    pub fn reset_timestamps(&self, pool: &TimestampPool) {
        unsafe { self.gpu.device.cmd_reset_query_pool(self.cmd, pool.raw, 0, pool.count) };
    }

    /// Writes timestamp `index` after all previous work.
    pub fn timestamp(&self, pool: &TimestampPool, index: u32) {
        unsafe {
            self.gpu.device.cmd_write_timestamp2(
                self.cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                pool.raw,
                index,
            )
        };
    }
}

/// A pool of timestamp queries, released when dropped.
#[derive(Debug)]
pub struct TimestampPool {
    raw: vk::QueryPool,
    count: u32,
    owner: Arc<Owner>,
}

impl Drop for TimestampPool {
    fn drop(&mut self) {
        // SAFETY: made on this device; its owner guarantees no submitted work uses it any more.
        unsafe { self.owner.device.destroy_query_pool(self.raw, None) };
    }
}

impl TimestampPool {
    /// `count` timestamps.
    pub fn new(gpu: &Gpu, count: u32) -> PlayResult<TimestampPool> {
        let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(count);
        let raw = unsafe { gpu.device.create_query_pool(&info, None) }
            .map_err(|e| vk_err("creating a query pool", e))?;
        Ok(TimestampPool { raw, count, owner: gpu.owner() })
    }

    /// The timestamps in nanoseconds (after the work completed).
    pub fn read_ns(&self, gpu: &Gpu) -> PlayResult<Vec<f64>> {
        let mut data = vec![0u64; self.count as usize];
        unsafe {
            gpu.device.get_query_pool_results(
                self.raw,
                0,
                &mut data,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .map_err(|e| vk_err("reading timestamps", e))?;
        Ok(data.iter().map(|&t| t as f64 * gpu.timestamp_period()).collect())
    }
}
