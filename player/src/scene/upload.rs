//! The staging ring: section bytes are copied from the mapped file into one of two host-visible
//! staging halves while the other half's copies run on the GPU (on the transfer queue when the
//! device has one). Large sections are split at half boundaries: buffers anywhere, images at
//! row boundaries.
//!
//! Dropping the ring waits for the batches it submitted; what is recorded and not submitted
//! never runs. After an error in an upload, what was recorded is not submitted either (its
//! commands may name a resource the error released): the batch is discarded.

use crate::gpu::vk;
use gpu_allocator::MemoryLocation;

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Buffer, CommandPool, Gpu, Image, ImageRows, Recorder, SemaphoreOp, Use};

/// Copies into staging start at multiples of this (buffer-to-image copies on transfer-only
/// queues need 4, texel blocks up to 16).
const ALIGN: u64 = 16;

struct Half {
    /// Dropped first: waits for the half's last batch, which reads `staging`.
    pool: CommandPool,
    staging: Buffer,
    used: u64,
    recording: bool,
}

/// Uploads bytes into buffers and images through a double-buffered staging ring.
pub struct Uploader<'g> {
    gpu: &'g Gpu,
    halves: [Half; 2],
    current: usize,
    timeline: vk::Semaphore,
    signalled: u64,
    /// Bytes uploaded so far.
    pub bytes: u64,
}

impl std::fmt::Debug for Uploader<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Uploader").field("bytes", &self.bytes).field("batches", &self.signalled).finish()
    }
}

impl<'g> Uploader<'g> {
    /// A ring of two halves of `half_bytes` each; `timeline` is signalled with increasing values
    /// as batches complete.
    pub fn new(gpu: &'g Gpu, half_bytes: u64, timeline: vk::Semaphore) -> PlayResult<Uploader<'g>> {
        let make = |i: usize| -> PlayResult<Half> {
            let staging = Buffer::new(
                gpu,
                &format!("staging {i}"),
                half_bytes,
                vk::BufferUsageFlags::TRANSFER_SRC,
                MemoryLocation::CpuToGpu,
            )?;
            Ok(Half { pool: CommandPool::new(gpu, gpu.upload_family())?, staging, used: 0, recording: false })
        };
        let halves = [make(0)?, make(1)?];
        Ok(Uploader { gpu, halves, current: 0, timeline, signalled: 0, bytes: 0 })
    }

    /// The same ring signalling values after `value` (a second upload on a timeline that an
    /// earlier one already advanced to `value`).
    pub fn after(mut self, value: u64) -> Uploader<'g> {
        self.signalled = value;
        self
    }

    fn capacity(&self) -> u64 {
        self.halves[0].staging.size
    }

    /// The recorder of the current half, starting it if needed.
    fn recorder(&mut self) -> PlayResult<Recorder<'g>> {
        let gpu = self.gpu;
        let half = &mut self.halves[self.current];
        if !half.recording {
            // `begin` waits for this half's previous batch, so its staging bytes are free.
            let rec = half.pool.begin(gpu)?;
            half.recording = true;
            half.used = 0;
            return Ok(rec);
        }
        Ok(Recorder::continuing(gpu, half.pool.cmd))
    }

    /// Submits the current half (if it recorded anything) and moves to the other.
    fn submit_current(&mut self) -> PlayResult {
        let half = &mut self.halves[self.current];
        if half.recording {
            self.signalled += 1;
            half.pool.submit(self.gpu, &[], &[SemaphoreOp::timeline(self.timeline, self.signalled)])?;
            half.recording = false;
        }
        self.current ^= 1;
        Ok(())
    }

    /// Reserves up to `want` bytes (at least `min`) in the current half, switching halves when
    /// it is full; returns (offset, bytes granted).
    fn reserve(&mut self, want: u64, min: u64) -> PlayResult<(u64, u64)> {
        if min > self.capacity() {
            return Err(PlayError::new(
                Exit::Gpu,
                format!("an upload step of {min} bytes exceeds the staging ring ({} bytes)", self.capacity()),
            ));
        }
        self.recorder()?;
        let used = self.halves[self.current].used.next_multiple_of(ALIGN);
        if used + min > self.capacity() {
            self.submit_current()?;
            self.recorder()?;
        }
        let capacity = self.capacity();
        let half = &mut self.halves[self.current];
        let offset = half.used.next_multiple_of(ALIGN);
        let granted = want.min(capacity - offset);
        half.used = offset + granted;
        Ok((offset, granted))
    }

    fn stage(&mut self, offset: u64, data: &[u8]) -> PlayResult {
        let half = &mut self.halves[self.current];
        let dst = half
            .staging
            .mapped()
            .ok_or_else(|| PlayError::new(Exit::Gpu, "the staging buffer is not host-visible"))?;
        dst[offset as usize..offset as usize + data.len()].copy_from_slice(data);
        self.bytes += data.len() as u64;
        Ok(())
    }

    /// Forgets the batch being recorded, if any, without submitting it.
    fn discard(&mut self) {
        for half in &mut self.halves {
            half.recording = false;
        }
    }

    /// `result`, discarding the batch being recorded when it is an error.
    fn checked(&mut self, result: PlayResult) -> PlayResult {
        if result.is_err() {
            self.discard();
        }
        result
    }

    /// Copies `data` into `dst` at `dst_offset`.
    pub fn buffer(&mut self, dst: &Buffer, dst_offset: u64, data: &[u8]) -> PlayResult {
        let copied = self.copy_buffer(dst, dst_offset, data);
        self.checked(copied)
    }

    fn copy_buffer(&mut self, dst: &Buffer, dst_offset: u64, data: &[u8]) -> PlayResult {
        let mut done = 0u64;
        while done < data.len() as u64 {
            let (offset, n) = self.reserve(data.len() as u64 - done, 1)?;
            self.stage(offset, &data[done as usize..(done + n) as usize])?;
            let half = &self.halves[self.current];
            Recorder::continuing(self.gpu, half.pool.cmd).copy_buffer(
                &half.staging,
                offset,
                dst,
                dst_offset + done,
                n,
            );
            done += n;
        }
        Ok(())
    }

    /// Fills `dst` with zeros (no staging needed).
    pub fn zero(&mut self, dst: &Buffer) -> PlayResult {
        let recorded = self.recorder().map(|rec| rec.fill_buffer(dst, 0, vk::WHOLE_SIZE, 0));
        self.checked(recorded)
    }

    /// Uploads an image's texels: `levels` lists (mip, layer, width, height, bytes) with rows
    /// tightly packed, `texel` bytes per texel. The image ends in SHADER_READ_ONLY layout.
    pub fn image(&mut self, image: &Image, texel: u64, levels: &[(u32, u32, u32, u32, &[u8])]) -> PlayResult {
        self.image_blocks(image, 1, texel, levels)
    }

    /// Uploads an image stored in `block × block` texel blocks of `block_bytes` each (1 and the
    /// texel size for uncompressed images): each level's rows of blocks tightly packed, the
    /// last row and column of blocks partial where the level's size is not a multiple of the
    /// block. Copies split at block-row boundaries. The mips from the lowest to the highest that
    /// `levels` names (every layer) end in SHADER_READ_ONLY layout; `levels` must write each of
    /// them. The other mips are left as they are: a texture's coarse levels, uploaded earlier and
    /// perhaps being sampled, keep their contents and layout while its finer levels arrive.
    pub fn image_blocks(
        &mut self,
        image: &Image,
        block: u32,
        block_bytes: u64,
        levels: &[(u32, u32, u32, u32, &[u8])],
    ) -> PlayResult {
        let copied = self.copy_image(image, block, block_bytes, levels);
        self.checked(copied)
    }

    fn copy_image(
        &mut self,
        image: &Image,
        block: u32,
        block_bytes: u64,
        levels: &[(u32, u32, u32, u32, &[u8])],
    ) -> PlayResult {
        let (Some(low), Some(high)) = (levels.iter().map(|l| l.0).min(), levels.iter().map(|l| l.0).max())
        else {
            return Ok(());
        };
        let written = image.mips(low, high - low + 1);
        // Only the levels written are discarded: the barrier orders nothing else.
        self.recorder()?.transition_raw(image.raw, written, Use::DISCARD, Use::TRANSFER_DST);
        for &(mip, layer, width, height, bytes) in levels {
            let row = width.div_ceil(block) as u64 * block_bytes;
            let block_rows = height.div_ceil(block);
            if bytes.len() as u64 != row * block_rows as u64 {
                return Err(PlayError::new(
                    Exit::BadInput,
                    format!(
                        "image level of {width}x{height} has {} bytes, expected {}",
                        bytes.len(),
                        row * block_rows as u64
                    ),
                ));
            }
            let mut y = 0u32;
            while y < block_rows {
                let (offset, n) = self.reserve(row * (block_rows - y) as u64, row)?;
                let rows = (n / row) as u32;
                // Give back the partial row the reservation may include.
                self.halves[self.current].used = offset + rows as u64 * row;
                let start = y as u64 * row;
                self.stage(offset, &bytes[start as usize..(start + rows as u64 * row) as usize])?;
                let half = &self.halves[self.current];
                // In texels: a copy's extent may end at the level's edge mid-block (Vulkan's rule
                // for block formats), and the buffer rows are whole blocks.
                let texel_y = y * block;
                let texel_rows = (rows * block).min(height - texel_y);
                Recorder::continuing(self.gpu, half.pool.cmd).copy_to_image(
                    &half.staging,
                    offset,
                    image,
                    ImageRows { mip, layer, y: texel_y, width, rows: texel_rows },
                );
                y += rows;
            }
        }
        self.recorder()?.transition_raw(image.raw, written, Use::TRANSFER_DST, Use::UPLOADED);
        Ok(())
    }

    /// Submits what is recorded; returns the timeline value that marks everything uploaded so far.
    pub fn flush(&mut self) -> PlayResult<u64> {
        self.submit_current()?;
        Ok(self.signalled)
    }

    /// Waits for every batch submitted, then releases the ring (as dropping it does, with the
    /// wait's error returned).
    pub fn finish(self) -> PlayResult {
        for half in &self.halves {
            half.pool.wait(self.gpu)?;
        }
        Ok(())
    }
}
