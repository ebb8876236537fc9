//! The environment on the GPU (`shaders/common/environment.glsl`): one storage buffer with the
//! header (irradiance harmonics included), the radiance map's texels and the prefiltered levels'
//! after them, and one with the sampling table. A file without an environment gets a header of
//! zeros (the shaders then use the constant sky) and one placeholder word and cell, so that every
//! pass binds the same layout either way. Uploaded with the geometry: the first frame reads it.

use kiln_format::KilnFile;
use kiln_format::environment::{Environment, EnvironmentCell, EnvironmentHeader};

use crate::error::PlayResult;
use crate::gpu::Buffer;
use crate::scene::upload::Uploader;

/// The environment's buffers.
#[derive(Debug)]
pub struct EnvironmentBuffers {
    /// `EnvironmentHeader`, then the map's and the prefiltered levels' `E5B9G9R9` texels.
    pub radiance: Buffer,
    /// `EnvironmentCell`s.
    pub table: Buffer,
    /// Whether the file has an environment.
    pub present: bool,
    /// Its mean radiance over the sphere of directions, as luminance (0 without one): what the
    /// reference path tracer weighs its light against the emitters' with.
    pub mean_luminance: f32,
}

impl EnvironmentBuffers {
    /// Creates the buffers of `file`'s environment (validated here) and records their upload.
    pub fn new(gpu: &crate::gpu::Gpu, file: &KilnFile, up: &mut Uploader) -> PlayResult<EnvironmentBuffers> {
        let env = Environment::read(file).map_err(super::bad)?;
        let placeholder_cell = [EnvironmentCell::default()];
        let (header, map, filtered, cells): (EnvironmentHeader, &[u32], &[u32], &[EnvironmentCell]) =
            match &env {
                Some(e) => (e.header, e.map, e.filtered, e.table),
                None => (EnvironmentHeader::default(), &[0], &[], &placeholder_cell),
            };
        let head = std::mem::size_of::<EnvironmentHeader>();
        let (map_bytes, filtered_bytes): (&[u8], &[u8]) =
            (bytemuck::cast_slice(map), bytemuck::cast_slice(filtered));
        let table_bytes: &[u8] = bytemuck::cast_slice(cells);
        let mut buffers = super::storage_buffers(
            gpu,
            &[
                ("environment", (head + map_bytes.len() + filtered_bytes.len()) as u64),
                ("environment table", table_bytes.len() as u64),
            ],
        )?
        .into_iter();
        let (radiance, table) = (buffers.next().expect("two buffers"), buffers.next().expect("two buffers"));
        up.buffer(&radiance, 0, bytemuck::bytes_of(&header))?;
        up.buffer(&radiance, head as u64, map_bytes)?;
        if !filtered_bytes.is_empty() {
            up.buffer(&radiance, (head + map_bytes.len()) as u64, filtered_bytes)?;
        }
        up.buffer(&table, 0, table_bytes)?;
        // The harmonics' band 0 (irradiance over π, whose cosine factor is 1 in band 0) times
        // the constant basis function: the mean radiance over all directions.
        let y00 = kiln_format::environment::sh_basis(glam::Vec3::Y)[0];
        let mean = header.sh[0].map(|c| c * y00);
        let mean_luminance = kiln_format::gpu::luminance([mean[0], mean[1], mean[2]]).max(0.0);
        Ok(EnvironmentBuffers { radiance, table, present: env.is_some(), mean_luminance })
    }

    /// The descriptor writes of the two buffers at `first` and `first + 1`.
    pub fn writes(&self, first: u32) -> [crate::gpu::Write<'_>; 2] {
        [crate::gpu::Write::Buffer(first, &self.radiance), crate::gpu::Write::Buffer(first + 1, &self.table)]
    }
}
