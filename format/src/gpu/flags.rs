//! Named values of the GPU structs' fields: kinds (light, phase function, shadow projection)
//! and bit sets (texture and frame flags). `glsl_layout` (the parent module) writes each as a
//! GLSL constant.

/// Light kinds in [`super::GpuLight::kind`].
#[derive(Debug)]
pub struct LightKinds;

impl LightKinds {
    /// Point light.
    pub const POINT: u32 = 0;
    /// Spot light.
    pub const SPOT: u32 = 1;
    /// Directional light.
    pub const DIRECTIONAL: u32 = 2;
    /// One-sided rectangle.
    pub const RECT: u32 = 3;
}

/// Phase functions in [`super::TothConstants::phase`].
#[derive(Debug)]
pub struct Phases;

impl Phases {
    /// Henyey–Greenstein with the medium's g.
    pub const HENYEY_GREENSTEIN: u32 = 0;
    /// Rayleigh: 3/(16π) (1 + cos² θ).
    pub const RAYLEIGH: u32 = 1;
}

/// Shadow projections in [`super::GpuShadow::projection`].
#[derive(Debug)]
pub struct ShadowKinds;

impl ShadowKinds {
    /// Orthographic (2D map).
    pub const ORTHOGRAPHIC: u32 = 0;
    /// Perspective (2D map).
    pub const PERSPECTIVE: u32 = 1;
    /// Cube map.
    pub const CUBE: u32 = 2;
}

/// Bits of [`super::GpuTexture::flags`].
#[derive(Debug)]
pub struct TextureFlags;

impl TextureFlags {
    /// Wrap mode along u in bits 0–1 (0 repeat, 1 mirrored repeat, 2 clamp).
    pub const WRAP_U_SHIFT: u32 = 0;
    /// Wrap mode along v in bits 2–3.
    pub const WRAP_V_SHIFT: u32 = 2;
    /// Texels are sRGB-encoded.
    pub const SRGB: u32 = 1 << 4;
    /// Bilinear filtering (else nearest).
    pub const LINEAR: u32 = 1 << 5;
    /// Mip levels stored from `offset` (level after level, each `max(1, size >> l)`) in bits 8–12.
    pub const LEVELS_SHIFT: u32 = 8;
    /// [`crate::sections::PixelFormat`] number in bits 13–14 (0 RGBA8, 1 BC7, 2 BC5, 3 BC4).
    pub const FORMAT_SHIFT: u32 = 13;
    /// [`crate::sections::Swizzle`] of the sampled R, G, B, A in bits 16–27, three bits each
    /// (R lowest).
    pub const SWIZZLE_SHIFT: u32 = 16;
}

/// Bits of `FrameConstants::size.w`.
#[derive(Debug)]
pub struct FrameFlags;

impl FrameFlags {
    /// Shadows from the baked shadow maps.
    pub const SHADOW_MAPS: u32 = 1 << 0;
    /// Shadows from the ray-traced visibility image (one layer per light).
    pub const RT_SHADOWS: u32 = 1 << 1;
    /// Ambient occlusion from the ray-traced AO image.
    pub const RT_AO: u32 = 1 << 2;
    /// Glossy reflections from the ray-traced reflection image.
    pub const RT_REFLECTIONS: u32 = 1 << 3;
    /// The reflection image has half the width and height.
    pub const REFLECTIONS_HALF: u32 = 1 << 4;
    /// Diffuse global illumination from the ray-traced GI image: it replaces the sky's diffuse
    /// ambient (and the AO that would darken it).
    pub const RT_GI: u32 = 1 << 5;
    /// Diffuse light gathered in screen space (the GI image): added to the sky's diffuse
    /// ambient, which AO still darkens.
    pub const SCREEN_GI: u32 = 1 << 6;
    /// Screen-space reflections in the reflection image: rgb the incoming radiance along the
    /// mirror direction, a the confidence in it; the split-sum ambient makes up the rest.
    pub const SCREEN_REFLECTIONS: u32 = 1 << 7;
    /// The light of the emissive triangles at the visible surfaces from the direct-light image
    /// (`--direct`): the composition adds it, and the GI pass leaves out the emission its first
    /// rays hit, so that every path counts once.
    pub const RT_DIRECT: u32 = 1 << 8;
    /// The probes' irradiance along each pixel's mirror direction in the probe-specular image
    /// (`--gi probes`): the split sum's incoming radiance where no reflection was traced or seen
    /// on screen, in place of the sky's (shaped by the environment's own sharpness there).
    pub const PROBE_SPECULAR: u32 = 1 << 9;
}
