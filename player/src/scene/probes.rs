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

/// How much of the light the probes saw came straight from emissive surfaces: per probe that is
/// on, the luminance of its second irradiance layer (the emitters seen directly) over both
/// layers', summed over its interior texels; the largest of those shares. `None` for a volume of
/// one layer (nothing emits) or no probe with light.
pub fn emitted_share(volume: &ProbeVolume) -> Option<f32> {
    let h = &volume.header;
    if h.layers < 2 {
        return None;
    }
    let n = h.irradiance_texels;
    let tile = n + 2;
    let [width, height, _] = h.irradiance_extent();
    let luminance = |t: u32| {
        let [r, g, b] = kiln_format::probes::decode_rgb9e5(t);
        kiln_format::gpu::luminance([r, g, b]) as f64
    };
    let mut largest: Option<f32> = None;
    for z in 0..h.dims[2] {
        for y in 0..h.dims[1] {
            for x in 0..h.dims[0] {
                if volume.states[h.index(x, y, z)].active != 1.0 {
                    continue;
                }
                let mut sums = [0.0f64; 2];
                for (layer, sum) in sums.iter_mut().enumerate() {
                    let slice = (layer as u32 * h.dims[2] + z) as usize * (width * height) as usize;
                    for j in 0..n {
                        let row = slice + ((y * tile + 1 + j) * width) as usize;
                        for i in 0..n {
                            let t = volume
                                .irradiance
                                .get(row + (x * tile + 1 + i) as usize)
                                .copied()
                                .unwrap_or(0);
                            *sum += luminance(t);
                        }
                    }
                }
                let total = sums[0] + sums[1];
                if total > 0.0 && total.is_finite() {
                    let share = (sums[1] / total) as f32;
                    largest = Some(largest.map_or(share, |l| l.max(share)));
                }
            }
        }
    }
    largest
}
