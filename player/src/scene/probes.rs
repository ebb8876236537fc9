//! The irradiance probe volume on the GPU: the irradiance and visibility atlases as sampled
//! 2D-array images (one layer per z slice of probes, the irradiance's second layer set after the
//! first), bilinearly filtered within each tile (the one-texel borders make the octahedral
//! edges wrap), and the probes' states (offset, on) as a storage buffer; read by `--gi probes`.

use kiln_format::gpu::ProbeConstants;
use kiln_format::probes::{ProbeHeader, ProbeVolume};

use crate::error::PlayResult;
use crate::gpu::{Buffer, Gpu, Image, vk};
use crate::scene::upload::Uploader;

/// The probe volume's GPU resources.
#[derive(Debug)]
pub struct ProbeImages {
    /// The header.
    pub header: ProbeHeader,
    /// E5B9G9R9 irradiance (mean cosine-weighted radiance), `dims[2] × layers` layers.
    pub irradiance: Image,
    /// Binary16 (mean, mean square) distance in spacings, `dims[2]` layers.
    pub visibility: Image,
    /// `vec4` (offset, on) per probe.
    pub states: Buffer,
}

impl ProbeImages {
    /// Creates the resources of `volume` and records their upload.
    pub fn new(gpu: &Gpu, volume: &ProbeVolume, up: &mut Uploader) -> PlayResult<ProbeImages> {
        let h = volume.header;
        let mut image = |name, format, [w, hgt, layers]: [u32; 3], texels: &[u8]| -> PlayResult<Image> {
            let mut desc = super::sampled_desc(format, w, hgt, 1, layers, false);
            desc.array = true;
            let image = Image::new(gpu, name, desc)?;
            let layer_bytes = w as usize * hgt as usize * 4;
            let layers: Vec<(u32, u32, u32, u32, &[u8])> = (0..layers)
                .map(|l| (0, l, w, hgt, &texels[l as usize * layer_bytes..(l as usize + 1) * layer_bytes]))
                .collect();
            up.image(&image, 4, &layers)?;
            Ok(image)
        };
        let irradiance = image(
            "probe irradiance",
            vk::Format::E5B9G9R9_UFLOAT_PACK32,
            h.irradiance_extent(),
            bytemuck::cast_slice(volume.irradiance),
        )?;
        let visibility = image(
            "probe visibility",
            vk::Format::R16G16_SFLOAT,
            h.visibility_extent(),
            bytemuck::cast_slice(volume.visibility),
        )?;
        let bytes: &[u8] = bytemuck::cast_slice(volume.states);
        let states = super::storage_buffers(gpu, &[("probe states", bytes.len() as u64)])?.remove(0);
        up.buffer(&states, 0, bytes)?;
        Ok(ProbeImages { header: h, irradiance, visibility, states })
    }

    /// The lookup's constants, with the biases in spacings.
    pub fn constants(&self, normal_bias: f32, view_bias: f32) -> ProbeConstants {
        let h = &self.header;
        ProbeConstants {
            origin: h.origin,
            spacing: h.spacing,
            dims: h.dims,
            layers: h.layers,
            irradiance_texels: h.irradiance_texels,
            visibility_texels: h.visibility_texels,
            normal_bias: normal_bias * h.spacing,
            view_bias: view_bias * h.spacing,
        }
    }
}
