//! Material layout shared with the player's shaders.

use bytemuck::{Pod, Zeroable};

/// Texture slot value meaning "no texture".
pub const NO_TEXTURE: u32 = u32::MAX;

/// How a material's alpha is used (glTF `alphaMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum AlphaMode {
    /// Alpha ignored.
    Opaque = 0,
    /// Alpha below `alpha_cutoff` discards.
    Mask = 1,
    /// Alpha blends.
    Blend = 2,
}

/// Bits of [`GpuMaterial::flags`].
#[derive(Debug)]
pub struct MaterialFlags;

impl MaterialFlags {
    /// Both faces are shaded (glTF `doubleSided`).
    pub const DOUBLE_SIDED: u32 = 1 << 0;
    /// Bits 1..3: [`AlphaMode`].
    pub const ALPHA_MODE_SHIFT: u32 = 1;
    /// Mask of the alpha-mode bits.
    pub const ALPHA_MODE_MASK: u32 = 0b11 << 1;
    /// Pure Lambertian diffuse, no specular lobe (OBJ materials with `Ks 0 0 0`).
    pub const DIFFUSE_ONLY: u32 = 1 << 3;
    /// [`GpuMaterial::specular`] holds the dielectric's own reflectance (glTF
    /// `KHR_materials_ior`, `KHR_materials_specular`); without it the dielectric reflects as
    /// glTF's core material does (F0 0.04, F90 1). Format 1.7.
    pub const SPECULAR: u32 = 1 << 4;
    /// Every flag bit defined in this version.
    pub const ALL: u32 = Self::DOUBLE_SIDED | Self::ALPHA_MODE_MASK | Self::DIFFUSE_ONLY | Self::SPECULAR;
}

/// A metallic-roughness PBR material. 112 bytes; std430-compatible (vec4, vec3 + float, scalars).
/// `MATL` version 3 (format 1.9); version 2 (format 1.8) held the first 96 bytes, version 1
/// (formats 1.0 to 1.7) the first 80 ([`GpuMaterial::from_words`] reads them).
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct GpuMaterial {
    /// Linear RGBA base colour factor.
    pub base_color: [f32; 4],
    /// Emitted radiance, W/(sr·m²) per linear RGB channel (emissive factor × strength).
    pub emission: [f32; 3],
    /// Metalness factor in [0, 1].
    pub metallic: f32,
    /// Perceptual roughness factor in [0, 1]; GGX α = roughness².
    pub roughness: f32,
    /// Alpha threshold for [`AlphaMode::Mask`].
    pub alpha_cutoff: f32,
    /// Scale of the tangent-space normal map's xy.
    pub normal_scale: f32,
    /// Strength of the occlusion texture.
    pub occlusion_strength: f32,
    /// Texture numbers (or [`NO_TEXTURE`]); base colour is sRGB, the others linear.
    pub base_color_texture: u32,
    /// Metalness in B, roughness in G (glTF).
    pub metallic_roughness_texture: u32,
    /// Tangent-space normal map.
    pub normal_texture: u32,
    /// Ambient occlusion in R.
    pub occlusion_texture: u32,
    /// Emission colour (sRGB), multiplied by `emission`.
    pub emissive_texture: u32,
    /// [`MaterialFlags`].
    pub flags: u32,
    /// With [`MaterialFlags::SPECULAR`], the dielectric (non-metal) part's Schlick reflectance
    /// at normal incidence F0 (linear RGB) and at grazing incidence F90, as four IEEE half floats
    /// in [0, 1]: F0.r and F0.g in word 0 (low half first), F0.b and F90 in word 1
    /// ([`GpuMaterial::dielectric`]). Zero without the flag.
    pub specular: [u32; 2],
    /// Clear coat layer's strength in [0, 1] (glTF `KHR_materials_clearcoat`'s
    /// `clearcoatFactor`); 0 without a coat. Format 1.8.
    pub clearcoat: f32,
    /// The coat's perceptual roughness in [0, 1] (`clearcoatRoughnessFactor`); GGX α = its square.
    pub clearcoat_roughness: f32,
    /// Texture whose R multiplies `clearcoat` (linear), or [`NO_TEXTURE`].
    pub clearcoat_texture: u32,
    /// Texture whose G multiplies `clearcoat_roughness` (linear), or [`NO_TEXTURE`].
    pub clearcoat_roughness_texture: u32,
    /// Fraction of the dielectric's non-reflected light that passes through the surface, in
    /// [0, 1] (glTF `KHR_materials_transmission`'s `transmissionFactor`); thin-walled, tinted
    /// by the base colour. Format 1.9.
    pub transmission: f32,
    /// Texture whose R multiplies `transmission` (linear), or [`NO_TEXTURE`].
    pub transmission_texture: u32,
    /// Zero; what the std430 array stride (a multiple of 16 bytes) leaves.
    pub reserved: [u32; 2],
}

const _: () = assert!(size_of::<GpuMaterial>() == 112);

/// The record sizes of `MATL`'s versions, in 32-bit words: version 1 (formats 1.0 to 1.7) 20,
/// version 2 (1.8, the clear coat) 24, version 3 (1.9, transmission) 28.
pub fn material_words(version: u16) -> usize {
    match version {
        1 => size_of::<GpuMaterialV1>() / 4,
        2 => size_of::<GpuMaterialV2>() / 4,
        _ => size_of::<GpuMaterial>() / 4,
    }
}

/// A record of `MATL` version 1 (formats 1.0 to 1.7): [`GpuMaterial`]'s first 20 words.
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct GpuMaterialV1 {
    /// The words as stored.
    pub words: [u32; 20],
}

/// A record of `MATL` version 2 (format 1.8): [`GpuMaterial`]'s first 24 words.
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct GpuMaterialV2 {
    /// The words as stored.
    pub words: [u32; 24],
}

impl GpuMaterial {
    /// A material from a record of an older `MATL` version (its first `words.len()` words, see
    /// [`material_words`]): the fields that version lacks take the values that mean "absent"
    /// (no coat, no transmission).
    pub fn from_words(words: &[u32]) -> GpuMaterial {
        // The default holds them: no coat, no transmission, no textures for either.
        let mut all: [u32; size_of::<GpuMaterial>() / 4] = bytemuck::cast(GpuMaterial::default());
        let n = words.len().min(all.len());
        all[..n].copy_from_slice(&words[..n]);
        bytemuck::cast(all)
    }
}

/// How many texture slots a material has ([`GpuMaterial::textures`]).
pub const MATERIAL_SLOTS: usize = 8;

/// glTF's dielectric reflectance at normal incidence without `KHR_materials_ior`/`specular`
/// (an index of refraction of 1.5).
pub const DIELECTRIC_F0: [f32; 3] = [0.04; 3];

impl Default for GpuMaterial {
    fn default() -> Self {
        GpuMaterial {
            base_color: [1.0; 4],
            emission: [0.0; 3],
            metallic: 1.0,
            roughness: 1.0,
            alpha_cutoff: 0.5,
            normal_scale: 1.0,
            occlusion_strength: 1.0,
            base_color_texture: NO_TEXTURE,
            metallic_roughness_texture: NO_TEXTURE,
            normal_texture: NO_TEXTURE,
            occlusion_texture: NO_TEXTURE,
            emissive_texture: NO_TEXTURE,
            flags: 0,
            specular: [0; 2],
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            clearcoat_texture: NO_TEXTURE,
            clearcoat_roughness_texture: NO_TEXTURE,
            transmission: 0.0,
            transmission_texture: NO_TEXTURE,
            reserved: [0; 2],
        }
    }
}

impl GpuMaterial {
    /// The texture slots, in field order (the G-buffer's bindings 0 to 7).
    pub fn textures(&self) -> [u32; MATERIAL_SLOTS] {
        [
            self.base_color_texture,
            self.metallic_roughness_texture,
            self.normal_texture,
            self.occlusion_texture,
            self.emissive_texture,
            self.clearcoat_texture,
            self.clearcoat_roughness_texture,
            self.transmission_texture,
        ]
    }

    /// The dielectric's (F0 RGB, F90): glTF's core 0.04 and 1 unless [`MaterialFlags::SPECULAR`]
    /// says [`GpuMaterial::specular`] holds them.
    pub fn dielectric(&self) -> ([f32; 3], f32) {
        if self.flags & MaterialFlags::SPECULAR == 0 {
            return (DIELECTRIC_F0, 1.0);
        }
        let h = |w: u32, high: bool| half::f16::from_bits((if high { w >> 16 } else { w }) as u16).to_f32();
        let [a, b] = self.specular;
        ([h(a, false), h(a, true), h(b, false)], h(b, true))
    }

    /// Stores the dielectric's F0 and F90 (each clamped to [0, 1]; NaN as 0) and sets the flag;
    /// the core values clear it, so that such materials keep their old bytes.
    pub fn set_dielectric(&mut self, f0: [f32; 3], f90: f32) {
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let (f0, f90) = (f0.map(unit), unit(f90));
        let bits = |v: f32| u32::from(half::f16::from_f32(v).to_bits());
        if (f0, f90) == (DIELECTRIC_F0, 1.0) {
            self.flags &= !MaterialFlags::SPECULAR;
            self.specular = [0; 2];
        } else {
            self.flags |= MaterialFlags::SPECULAR;
            self.specular = [bits(f0[0]) | bits(f0[1]) << 16, bits(f0[2]) | bits(f90) << 16];
        }
    }

    /// Whether what lies behind the surface shows through it: alpha-blended (glTF BLEND) with
    /// a base colour alpha below 1 or a base colour texture (whose alpha may be), or
    /// transmitting (`KHR_materials_transmission`). The raster frame draws such surfaces in a
    /// layer of their own over the opaque ones (the player's see-through layer).
    pub fn see_through(&self) -> bool {
        let blended = self.alpha_mode() == Some(AlphaMode::Blend)
            && (self.base_color[3] < 1.0 || self.base_color_texture != NO_TEXTURE);
        let transmits = self.transmission > 0.0 && !self.diffuse_only();
        blended || transmits
    }

    /// Whether the material is pure Lambertian, without a specular lobe
    /// ([`MaterialFlags::DIFFUSE_ONLY`]).
    pub fn diffuse_only(&self) -> bool {
        self.flags & MaterialFlags::DIFFUSE_ONLY != 0
    }

    /// The alpha mode, if the bits hold a defined one.
    pub fn alpha_mode(&self) -> Option<AlphaMode> {
        match (self.flags & MaterialFlags::ALPHA_MODE_MASK) >> MaterialFlags::ALPHA_MODE_SHIFT {
            0 => Some(AlphaMode::Opaque),
            1 => Some(AlphaMode::Mask),
            2 => Some(AlphaMode::Blend),
            _ => None,
        }
    }
}
