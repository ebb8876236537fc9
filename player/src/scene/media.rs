//! Participating media on the GPU: the media table (`GpuMedium`s, from the manifest) and the
//! light-visibility volumes (`MVIS` sections) in one storage buffer of bytes, read by the
//! ray-marched media pass (and the table by the reference path tracer).

use kiln_format::gpu::GpuMedium;
use kiln_format::manifest::Manifest;

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Buffer, Gpu};
use crate::scene::upload::Uploader;

/// The manifest's media as the shaders read them.
pub fn table(manifest: &Manifest) -> Vec<GpuMedium> {
    manifest
        .media
        .iter()
        .map(|m| {
            let v4 = |v: [f32; 3], w: f32| [v[0], v[1], v[2], w];
            GpuMedium {
                min: v4(m.bounds.min, m.g),
                max: v4(m.bounds.max, 0.0),
                sigma_a: v4(m.sigma_a, 0.0),
                sigma_s: v4(m.sigma_s, 0.0),
            }
        })
        .collect()
}

/// The media buffers of a scene.
#[derive(Debug)]
pub struct MediaBuffers {
    /// `GpuMedium` per medium.
    pub table: Buffer,
    /// Every visibility volume's bytes (x fastest), each starting on a 4-byte boundary.
    pub volumes: Buffer,
    /// Per light (manifest order): the first byte of its volume in `volumes`, −1 for none.
    pub volume_of: Buffer,
    /// Media in the table.
    pub count: u32,
    /// The medium the volumes cover (`u32::MAX`: no volumes).
    pub volume_medium: u32,
    /// Cells of each volume per axis.
    pub dims: [u32; 3],
    /// Entries of `volume_of`.
    pub lights: u32,
    /// The first byte of the sky's red grid in `volumes` (`u32::MAX`: none).
    pub sky_volume: u32,
    /// Where section `MVIS#i` goes in `volumes`.
    offsets: Vec<u64>,
}

impl MediaBuffers {
    /// Allocates the buffers of `manifest`'s media and uploads the table and light map; the
    /// volumes (when `volumes`: a technique reads them) arrive with their sections
    /// ([`MediaBuffers::upload_volume`]).
    pub fn new(gpu: &Gpu, manifest: &Manifest, volumes: bool, up: &mut Uploader) -> PlayResult<MediaBuffers> {
        let media = table(manifest);
        let (dims, volume_medium, lights_with) = match &manifest.media_visibility {
            Some(v) if volumes => (v.dims, v.medium, v.lights.clone()),
            _ => ([0; 3], u32::MAX, Vec::new()),
        };
        // Validated with the manifest: dims within the resolution limit, lights in range.
        let volume_bytes = dims.iter().map(|&d| d as u64).product::<u64>();
        let stride = volume_bytes.next_multiple_of(4);
        let offsets: Vec<u64> = (0..lights_with.len() as u64).map(|i| i * stride).collect();
        let mut volume_of = vec![-1i32; manifest.lights.len()];
        // The sky's grids: consecutive, red first (validated with the manifest).
        let sky = manifest.media_visibility.as_ref().filter(|_| volumes).and_then(|v| v.sky_index());
        let sky_volume = sky.and_then(|i| u32::try_from(offsets[i]).ok()).unwrap_or(u32::MAX);
        for (i, &light) in lights_with.iter().enumerate() {
            let at = i32::try_from(offsets[i]).map_err(|_| {
                PlayError::new(Exit::BadInput, "the light-visibility volumes exceed 2 GiB: too many to march")
            })?;
            if let Some(slot) = volume_of.get_mut(light as usize) {
                *slot = at;
            }
        }
        let sizes = [
            ("media", std::mem::size_of_val(media.as_slice()) as u64),
            ("visibility volumes", stride * lights_with.len() as u64),
            ("volume of each light", volume_of.len() as u64 * 4),
        ];
        let mut it = super::storage_buffers(gpu, &sizes)?.into_iter();
        let mut next = || it.next().expect("one buffer per size");
        let buffers = MediaBuffers {
            table: next(),
            volumes: next(),
            volume_of: next(),
            count: media.len() as u32,
            volume_medium,
            dims,
            lights: volume_of.len() as u32,
            sky_volume,
            offsets,
        };
        up.buffer(&buffers.table, 0, bytemuck::cast_slice(&media))?;
        up.buffer(&buffers.volume_of, 0, bytemuck::cast_slice(&volume_of))?;
        Ok(buffers)
    }

    /// Uploads section `MVIS#index`.
    pub fn upload_volume(&self, index: u32, bytes: &[u8], up: &mut Uploader) -> PlayResult {
        let expected = self.dims.iter().map(|&d| d as u64).product::<u64>();
        match self.offsets.get(index as usize) {
            Some(&at) if bytes.len() as u64 == expected => up.buffer(&self.volumes, at, bytes),
            _ => Err(PlayError::new(
                Exit::BadInput,
                format!(
                    "invalid .kiln file: media-visibility section {index} has {} bytes; the manifest lists {} volumes of {expected}",
                    bytes.len(),
                    self.offsets.len()
                ),
            )),
        }
    }
}
