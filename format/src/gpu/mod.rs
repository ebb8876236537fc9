//! Layouts the player's shaders read, defined once here. Each struct is declared with the GLSL
//! type of every field; `glsl_layout()` emits the matching GLSL declarations, which the player's
//! `shaders/common/layout.glsl` must equal (a test fails on drift), and a test checks every Rust
//! offset against the std430/std140 offsets GLSL assigns.

use bytemuck::{Pod, Zeroable};

/// A struct shared with GLSL: its fields as (name, GLSL type, Rust offset, Rust size).
pub trait GlslStruct {
    /// Struct name in both languages.
    const NAME: &'static str;
    /// Fields in declaration order.
    fn fields() -> Vec<(&'static str, &'static str, usize, usize)>;
    /// Size in bytes.
    fn size() -> usize;
}

macro_rules! gpu_struct {
    ($(#[$m:meta])* pub struct $name:ident { $($(#[$fm:meta])* pub $field:ident : $ty:ty => $glsl:literal,)* }) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
        #[repr(C)]
        pub struct $name {
            $($(#[$fm])* pub $field: $ty,)*
        }

        impl GlslStruct for $name {
            const NAME: &'static str = stringify!($name);
            fn fields() -> Vec<(&'static str, &'static str, usize, usize)> {
                vec![$((stringify!($field), $glsl, core::mem::offset_of!($name, $field), size_of::<$ty>()),)*]
            }
            fn size() -> usize {
                size_of::<$name>()
            }
        }
    };
}

mod emitters;
pub use emitters::{EmissiveFlags, EmitterKinds, GpuEmissive, GpuEmitter, emitted_power, luminance};
mod bake;
pub use bake::{BakeCell, BakeParams, bake_layout};
mod environment;
pub use environment::{EnvironmentCell, EnvironmentHeader};
mod flags;
pub use flags::{FrameFlags, LightKinds, Phases, ShadowKinds, TextureFlags};

gpu_struct! {
    /// One analytic light, as the direct-light pass reads it (std430, 80 bytes). Units as in the
    /// manifest: `intensity × color` is W/sr (point, spot), W/m² (directional) or W/(sr·m²) (rect).
    pub struct GpuLight {
        /// Position (point, spot, rect centre).
        pub position: [f32; 3] => "vec3",
        /// [`LightKinds`].
        pub kind: u32 => "uint",
        /// Unit direction the light travels (directional, spot) or faces (rect).
        pub direction: [f32; 3] => "vec3",
        /// Cut-off distance, 0 = none.
        pub range: f32 => "float",
        /// Linear RGB colour times intensity.
        pub radiance: [f32; 3] => "vec3",
        /// Index into the shadow records, −1 without a shadow map.
        pub shadow: i32 => "int",
        /// Rect: unit vector along the width.
        pub right: [f32; 3] => "vec3",
        /// Spot: cosine of the inner cone half-angle.
        pub cos_inner: f32 => "float",
        /// Spot: cosine of the outer cone half-angle.
        pub cos_outer: f32 => "float",
        /// Rect: width.
        pub width: f32 => "float",
        /// Rect: height.
        pub height: f32 => "float",
        /// Extent the ray-traced soft shadows sample (a player setting, not in the file): sphere
        /// radius of point and spot lights, angular radius in radians of directional lights.
        pub radius: f32 => "float",
    }
}

gpu_struct! {
    /// One shadow map's parameters (std430, 112 bytes); see FORMAT.md ("`SHDW`").
    pub struct GpuShadow {
        /// World to clip, column-major (2D maps).
        pub view_proj: [f32; 16] => "mat4",
        /// Ray origin: light position, or near-plane centre (orthographic).
        pub origin: [f32; 3] => "vec3",
        /// [`ShadowKinds`].
        pub projection: u32 => "uint",
        /// View axis.
        pub direction: [f32; 3] => "vec3",
        /// Texel footprint: world size (orthographic) or radians.
        pub texel: f32 => "float",
        /// Farthest distance.
        pub far: f32 => "float",
        /// Index into the 2D or the cube map array.
        pub slot: u32 => "uint",
        /// Texels per side.
        pub resolution: u32 => "uint",
        /// Zero.
        pub reserved: u32 => "uint",
    }
}

gpu_struct! {
    /// Per-frame constants (std140 uniform block, 320 bytes).
    pub struct FrameConstants {
        /// World to clip, column-major.
        pub view_proj: [f32; 16] => "mat4",
        /// Clip to world.
        pub inv_view_proj: [f32; 16] => "mat4",
        /// Camera position, w unused.
        pub camera: [f32; 4] => "vec4",
        /// Sky radiance, w = the participating media that dim the light reaching surfaces
        /// (entries of the direct pass's media buffer; 0 without a media technique).
        pub sky: [f32; 4] => "vec4",
        /// Image width, height, light count, flags.
        pub size: [u32; 4] => "uvec4",
        /// Exposure multiplier, BRDF table resolution (0: none), frame number, the roughness up
        /// to which ray-traced reflections replace the split-sum specular.
        pub params: [f32; 4] => "vec4",
        /// Unit right vector, w = tan(vfov / 2) · aspect: the camera ray through NDC (x, y) is
        /// forward + right · x · right.w + up · y · up.w (the projection's own mapping).
        pub camera_right: [f32; 4] => "vec4",
        /// Unit up vector, w = tan(vfov / 2).
        pub camera_up: [f32; 4] => "vec4",
        /// Unit forward vector, w unused.
        pub camera_forward: [f32; 4] => "vec4",
        /// This frame's clip coordinates (of `view_proj`, jitter included) to the previous
        /// frame's clip coordinates without its jitter (computed in f64): where a pixel's surface
        /// point was seen last frame.
        pub reproject: [f32; 16] => "mat4",
        /// x, y: where this frame's sample of each pixel lies relative to the pixel's centre, in
        /// pixels (the sub-pixel jitter of `--aa taa`; 0 otherwise); z: 1 when the camera has
        /// not moved since the previous frame (`reproject` is then the jitter alone), else 0;
        /// w: 1 when there is no previous frame (history is invalid), else 0.
        pub jitter: [f32; 4] => "vec4",
    }
}

gpu_struct! {
    /// Constants of the reference path tracer (std140 uniform block, 128 bytes).
    pub struct ReferenceConstants {
        /// Camera position, w = tan(vfov / 2) (perspective) or the view's half height
        /// (orthographic).
        pub eye: [f32; 4] => "vec4",
        /// Unit right vector, w = aspect ratio (width / height).
        pub right: [f32; 4] => "vec4",
        /// Unit up vector, w = 1 for an orthographic camera, else 0.
        pub up: [f32; 4] => "vec4",
        /// Unit forward vector, w unused.
        pub forward: [f32; 4] => "vec4",
        /// Sky radiance, w = the probability that next-event estimation at a surface samples the
        /// environment rather than the emitter table (one shadow ray per vertex).
        pub sky: [f32; 4] => "vec4",
        /// Image width, height, samples per pixel requested, emitter count (the index of the
        /// sample being taken is a push constant).
        pub size: [u32; 4] => "uvec4",
        /// Light count, maximum path length, seed, bounce limit (scattering events whose light
        /// counts; 0: unlimited, 1: direct light only).
        pub params: [u32; 4] => "uvec4",
        /// Participating media (entries of the `GpuMedium` buffer), then three unused words.
        pub media: [u32; 4] => "uvec4",
    }
}

gpu_struct! {
    /// A homogeneous participating medium filling an axis-aligned box, as the reference path
    /// tracer reads it (std430, 64 bytes). Where boxes overlap, their coefficients add.
    pub struct GpuMedium {
        /// Box minimum corner, w = Henyey–Greenstein anisotropy g.
        pub min: [f32; 4] => "vec4",
        /// Box maximum corner, w unused.
        pub max: [f32; 4] => "vec4",
        /// Absorption coefficient per scene unit (RGB), w unused.
        pub sigma_a: [f32; 4] => "vec4",
        /// Scattering coefficient per scene unit (RGB), w unused.
        pub sigma_s: [f32; 4] => "vec4",
    }
}

gpu_struct! {
    /// Push constants of the ray-marched media pass (`shaders/media/march.comp`; 28 bytes).
    pub struct MarchConstants {
        /// Steps along the view ray's part inside each medium.
        pub steps: u32 => "uint",
        /// Entries of the `GpuMedium` buffer.
        pub media: u32 => "uint",
        /// The medium the light-visibility volumes cover (`u32::MAX`: none).
        pub volume_medium: u32 => "uint",
        /// Volume cells along x.
        pub dims_x: u32 => "uint",
        /// Volume cells along y.
        pub dims_y: u32 => "uint",
        /// Volume cells along z.
        pub dims_z: u32 => "uint",
        /// Lights with a volume: `volume_of[light]` is its first byte in the volume buffer, −1
        /// without one (unshadowed in the medium).
        pub lights: u32 => "uint",
        /// The first byte of the sky's red grid in the volume buffer (green and blue follow, one
        /// grid's bytes rounded up to 4 apart); `u32::MAX`: no sky grids, the sky scatters nothing.
        pub sky_volume: u32 => "uint",
    }
}

gpu_struct! {
    /// Push constants of the image-space god-ray passes (`shaders/mitchell/*`,
    /// `shaders/sousa/*`; 28 bytes): one light's radial blur per dispatch.
    pub struct GodRayConstants {
        /// The light (index into the light buffer) whose shafts this dispatch makes.
        pub light: u32 => "uint",
        /// Samples along the pixel's path towards the light (Mitchell n, Sousa TAPS).
        pub samples: u32 => "uint",
        /// Mitchell: the density (the march covers 1/density of the way to the light); Sousa:
        /// this pass's step in texture coordinates.
        pub step: f32 => "float",
        /// Mitchell: exposure per sample; Sousa: brightness.
        pub gain: f32 => "float",
        /// Mitchell: the decay per sample.
        pub decay: f32 => "float",
        /// Mitchell: the radius of the lights' emitting proxies; Sousa: the distance that maps
        /// to depth 1 (the sky's).
        pub extent: f32 => "float",
        /// Entries of the `GpuMedium` buffer (the shafts take medium 0's albedo and phase).
        pub media: u32 => "uint",
    }
}

gpu_struct! {
    /// Push constants of the shadow-map ray march (`shaders/toth/*`; 16 bytes).
    pub struct TothConstants {
        /// Samples along each view ray's part inside the media (before interleaving).
        pub samples: u32 => "uint",
        /// Side of the interleaving block: each pixel of a block takes every block²-th sample.
        pub block: u32 => "uint",
        /// Phase function: 0 the medium's Henyey–Greenstein, 1 Rayleigh.
        pub phase: u32 => "uint",
        /// Entries of the `GpuMedium` buffer.
        pub media: u32 => "uint",
    }
}

gpu_struct! {
    /// Push constants of the screen-space AO passes (`shaders/pyramid/*`, `shaders/sao/*`,
    /// `shaders/gtao/*`, `shaders/ao/*`; 32 bytes).
    pub struct ScreenAoConstants {
        /// AO radius in world units.
        pub radius: f32 => "float",
        /// SAO: turns of the sample spiral (τ).
        pub turns: f32 => "float",
        /// SAO: samples per pixel (N); GTAO: slices per pixel.
        pub count: u32 => "uint",
        /// GTAO: steps along each side of a slice.
        pub steps: u32 => "uint",
        /// Screen pixels per AO pixel along each axis (1 full resolution, 2 half).
        pub step: u32 => "uint",
        /// Depth pyramid: the level this dispatch writes.
        pub level: u32 => "uint",
        /// Depth pyramid: 1 to pick each texel by the seed's voting filter (the child agreeing
        /// best with its 4 × 4 neighbourhood), 0 for nearest on the rotated grid.
        pub voting: u32 => "uint",
        /// Depth pyramid: 1 to build the normals pyramid beside it.
        pub normals: u32 => "uint",
    }
}

gpu_struct! {
    /// Push constants of screen-space GI and the lit-radiance pyramid (`shaders/ssgi/*`,
    /// `shaders/lit/*`; 48 bytes).
    pub struct ScreenGiConstants {
        /// The pyramid level this dispatch reads or writes.
        pub level: u32 => "uint",
        /// The finest level gathered (the GI resolution: 0 full, 1 half, 2 quarter).
        pub base: u32 => "uint",
        /// The coarsest level gathered.
        pub top: u32 => "uint",
        /// Spiral samples per pixel and level.
        pub samples: u32 => "uint",
        /// Sample radius in pixels of the level gathered.
        pub radius: f32 => "float",
        /// Frames already averaged into the GI at this camera (0: this frame replaces them).
        pub accumulated: u32 => "uint",
        /// Per-frame random seed.
        pub seed: u32 => "uint",
        /// The most frames the running mean averages (later frames weigh 1/cap).
        pub cap: u32 => "uint",
        /// Seed 000's distance fall-off (r² → r^2.5 beyond one unit) in place of visibility:
        /// 1 on, 0 off.
        pub falloff: u32 => "uint",
        /// 1: every 8 × 8 block of texels turns its spirals by one random angle (neighbours read
        /// neighbouring texels: coherent fetches, noise correlated within the block); 0: every
        /// texel by its own, as the seed.
        pub tiled: u32 => "uint",
        /// The lit pyramid's level 0: 1 takes this frame's radiance where it lies (the pyramid's
        /// second making on a frame without history, after the direct pass lit it), 0 the
        /// previous frame's, reprojected.
        pub current: u32 => "uint",
        /// Padding.
        pub pad: u32 => "uint",
    }
}

gpu_struct! {
    /// Push constants of the screen-space reflections (`shaders/hiz/*`, `shaders/ssr/*`;
    /// 20 bytes).
    pub struct SsrConstants {
        /// The most iterations of the hierarchical march per pixel.
        pub steps: u32 => "uint",
        /// Surfaces rougher than this keep the split-sum ambient (confidence 0).
        pub max_roughness: f32 => "float",
        /// How far a ray may pass behind the surface the depth buffer holds and still hit it, as
        /// a fraction of that surface's camera depth.
        pub thickness: f32 => "float",
        /// The pyramid's coarsest level.
        pub top: u32 => "uint",
        /// Hi-Z: the level this dispatch writes.
        pub level: u32 => "uint",
    }
}

gpu_struct! {
    /// Push constants of fast approximate anti-aliasing (`shaders/fxaa/*`; 16 bytes).
    pub struct FxaaConstants {
        /// How much of the sub-pixel blend (single-pixel features, the ends of thin lines)
        /// applies: 0 none, 1 all (Lottes's "subpix", 0.75 his default).
        pub subpix: f32 => "float",
        /// The smallest local contrast, relative to the brightest neighbour's perceptual luma,
        /// that counts as an edge.
        pub threshold: f32 => "float",
        /// The smallest local contrast that counts as an edge in the dark (perceptual luma).
        pub threshold_min: f32 => "float",
        /// Padding.
        pub pad: u32 => "uint",
    }
}

gpu_struct! {
    /// Push constants of the spatiotemporal denoiser (`shaders/denoise/*`; 32 bytes).
    pub struct DenoiseConstants {
        /// Signals filtered together (1 or 2: image arrays of two, sharing each tap's geometry).
        pub signals: u32 => "uint",
        /// Samples in every pixel's running mean (a still camera without reprojection); 0: read
        /// them per pixel from the reprojected history's samples image.
        pub samples: u32 => "uint",
        /// À-trous: the spacing of this iteration's taps in pixels (1, 2, 4, …).
        pub step: u32 => "uint",
        /// Bit i set: signal i is divided by the albedo's demodulator before filtering and
        /// multiplied back after; clear: it is filtered as it is.
        pub demodulate: u32 => "uint",
        /// 1: this iteration is the last and writes the output image.
        pub last: u32 => "uint",
        /// Luminance edge-stopping: differences are measured in this many standard deviations
        /// of the noise (SVGF's σ_l).
        pub sigma_luminance: f32 => "float",
        /// Normal edge-stopping: the exponent of max(0, n_p · n_q) (SVGF's σ_n).
        pub sigma_normal: f32 => "float",
        /// Depth edge-stopping: a tap's distance from the pixel's tangent plane is measured in
        /// this many pixel footprints (at the pixel).
        pub sigma_plane: f32 => "float",
    }
}

gpu_struct! {
    /// Push constants of the probe GI pass (`shaders/probes/gi.comp`; 48 bytes): the volume's
    /// header ([`crate::probes::ProbeHeader`]) and the lookup's biases.
    pub struct ProbeConstants {
        /// Grid point of probe (0, 0, 0).
        pub origin: [f32; 3] => "vec3",
        /// Distance between neighbouring probes.
        pub spacing: f32 => "float",
        /// Probes along x, y, z.
        pub dims: [u32; 3] => "uvec3",
        /// Irradiance layers (2: emissive surfaces' direct light in the second).
        pub layers: u32 => "uint",
        /// Interior texels of an irradiance tile's edge.
        pub irradiance_texels: u32 => "uint",
        /// Interior texels of a visibility tile's edge.
        pub visibility_texels: u32 => "uint",
        /// The lookup point moves this far along the surface normal (scene units).
        pub normal_bias: f32 => "float",
        /// … and this far towards the camera.
        pub view_bias: f32 => "float",
    }
}

gpu_struct! {
    /// Push constants of the hybrid ray-traced passes (`shaders/rt/*.comp`; 60 bytes).
    pub struct RtConstants {
        /// Frames already averaged into the accumulation images at this camera (0: this frame
        /// replaces them).
        pub accumulated: u32 => "uint",
        /// Per-frame random seed.
        pub seed: u32 => "uint",
        /// Ambient-occlusion ray length (world units).
        pub ao_radius: f32 => "float",
        /// Reflections: surfaces rougher than this are left to the split-sum ambient.
        pub max_roughness: f32 => "float",
        /// Lights with a ray-traced shadow layer (the first ones of the light buffer).
        pub shadow_lights: u32 => "uint",
        /// Pixels per reflection sample along each axis: 1 full resolution, 2 half.
        pub reflection_step: u32 => "uint",
        /// Lights whose shadow rays at reflection hits are traced in the separate, lean
        /// reflection-shadow pass (the first ones; any further ones are traced inline).
        pub reflection_lights: u32 => "uint",
        /// GI: scattering events after the primary surface whose light the estimate counts (1:
        /// what the first surface a ray from the primary surface hits emits and receives directly).
        pub gi_bounces: u32 => "uint",
        /// GI: entries of the emitter table (`GpuEmitter`s) its next-event estimation chooses from.
        pub emitters: u32 => "uint",
        /// Direct light of emissive surfaces: entries of the emissive-triangle table
        /// (`GpuEmissive`s) its candidates are drawn from.
        pub emissive: u32 => "uint",
        /// Direct light: candidates per pixel and frame (resampled importance sampling).
        pub direct_candidates: u32 => "uint",
        /// Direct light: neighbouring reservoirs combined per pixel (spatial reuse; 0: none).
        pub direct_spatial: u32 => "uint",
        /// Direct light: the previous frame's reservoir weighs at most this many times the
        /// candidates (temporal reuse; 0: none).
        pub direct_temporal: u32 => "uint",
        /// Direct light: 1 where shadow rays decide visibility, 0 for unshadowed light.
        pub direct_visibility: u32 => "uint",
        /// GI: the least roughness of the surfaces its paths hit (path regularisation; 0 off).
        pub gi_min_roughness: f32 => "float",
        /// Reflections: metal hits smoother than this trace their own specular lobe one bounce
        /// further (0: none; their lobe reads the probes or the sky).
        pub metal_bounce_roughness: f32 => "float",
    }
}

gpu_struct! {
    /// A texture in the texel buffer of the ray-traced passes (std430, 16 bytes): its mip chain
    /// as stored in its `TEXL` section (RGBA8 texels or BC blocks, as whole words) from `offset`.
    pub struct GpuTexture {
        /// First texel (in words).
        pub offset: u32 => "uint",
        /// Width.
        pub width: u32 => "uint",
        /// Height.
        pub height: u32 => "uint",
        /// [`TextureFlags`].
        pub flags: u32 => "uint",
    }
}

impl GpuTexture {
    /// The pixel format of its texels in the buffer (the [`TextureFlags::FORMAT_SHIFT`] bits,
    /// what the shaders read).
    pub fn pixel_format(&self) -> crate::sections::PixelFormat {
        use crate::sections::PixelFormat;
        PixelFormat::from_u32((self.flags >> TextureFlags::FORMAT_SHIFT) & 3).unwrap_or(PixelFormat::Rgba8)
    }
}

gpu_struct! {
    /// A vertex's attributes besides position and normal, as the player interleaves them from
    /// `UVS0` and `COL0` (std430, 16 bytes): the raster passes' second vertex stream and what
    /// the compute passes read at a hit.
    pub struct GpuVertexAttributes {
        /// Texture coordinates (zeros without `UVS0`).
        pub uv: [f32; 2] => "vec2",
        /// Colour: the `COL0` element's bytes, unorm16 R, G in word 0 and B, A in word 1, each
        /// first channel in the low half (`unpackUnorm2x16`); white without `COL0`.
        pub color: [u32; 2] => "uvec2",
    }
}

/// Shadow maps of each kind (2D and cube) the direct-light pass can bind: the length of its
/// `shadow_2d` and `shadow_cube` sampler arrays (`MAX_SHADOW_MAPS` in `layout.glsl`). Lights
/// beyond it are drawn without shadow maps.
pub const MAX_SHADOW_MAPS: usize = 8;

/// Lights that can have a ray-traced shadow layer (and, in the reflections, a shadow-ray layer);
/// further lights are drawn unshadowed (`MAX_RT_SHADOW_LIGHTS` in `layout.glsl`).
pub const MAX_RT_SHADOW_LIGHTS: usize = 16;

/// Lights whose shadow rays at the hits of metal hits' own reflections (the reflections' metal
/// bounce) are traced by the reflections' shadow kernel, the first ones; the shading kernel
/// traces any further ones inline (`REFLECTION_SECOND_HIT_LIGHTS` in `layout.glsl`). Each costs
/// an image layer at the reflections' resolution (23 MB at 1600 × 900).
pub const REFLECTION_SECOND_HIT_LIGHTS: usize = 4;

/// Alignment and size of a GLSL type under std430 (std140 differs only for arrays and structs,
/// which these layouts do not nest).
fn glsl_align_size(ty: &str) -> (usize, usize) {
    match ty {
        "float" | "uint" | "int" => (4, 4),
        "vec2" | "uvec2" | "ivec2" => (8, 8),
        "vec3" | "uvec3" | "ivec3" => (16, 12),
        "vec4" | "uvec4" | "ivec4" => (16, 16),
        "mat4" => (16, 64),
        "vec4[9]" => (16, 144),
        "double" => (8, 8),
        "dvec4" => (32, 32),
        other => panic!("GLSL type {other} has no layout rule here"),
    }
}

/// Offsets GLSL assigns to the fields of `T` (std430 / std140), and the struct size rounded to
/// its alignment.
pub fn glsl_offsets<T: GlslStruct>() -> (Vec<usize>, usize) {
    let mut offset = 0usize;
    let mut align_max = 4usize;
    let mut out = Vec::new();
    for (_, ty, _, _) in T::fields() {
        let (align, size) = glsl_align_size(ty);
        offset = offset.div_ceil(align) * align;
        out.push(offset);
        offset += size;
        align_max = align_max.max(align);
    }
    (out, offset.div_ceil(align_max) * align_max)
}

pub(crate) fn declare<T: GlslStruct>(out: &mut String) {
    out.push_str(&format!("struct {} {{\n", T::NAME));
    for (name, ty, offset, _) in T::fields() {
        out.push_str(&format!("    {ty} {name}; // offset {offset}\n"));
    }
    out.push_str(&format!("}}; // {} bytes\n\n", T::size()));
}

/// The GLSL declarations of every shared layout.
pub fn glsl_layout() -> String {
    let mut s = String::from(
        "// Generated by kiln_format::gpu::glsl_layout(); do not edit.\n// Layouts shared with kiln-format (format/src/gpu/, format/src/sections).\n#ifndef KILN_LAYOUT_GLSL\n#define KILN_LAYOUT_GLSL\n\n",
    );
    declare::<GpuLight>(&mut s);
    declare::<GpuShadow>(&mut s);
    declare::<FrameConstants>(&mut s);
    declare::<GpuMaterialLayout>(&mut s);
    declare::<ReferenceConstants>(&mut s);
    declare::<GpuEmitter>(&mut s);
    declare::<GpuEmissive>(&mut s);
    declare::<GpuMedium>(&mut s);
    declare::<GpuTexture>(&mut s);
    declare::<GpuVertexAttributes>(&mut s);
    declare::<RtConstants>(&mut s);
    declare::<MarchConstants>(&mut s);
    declare::<GodRayConstants>(&mut s);
    declare::<TothConstants>(&mut s);
    declare::<ScreenAoConstants>(&mut s);
    declare::<ScreenGiConstants>(&mut s);
    declare::<SsrConstants>(&mut s);
    declare::<DenoiseConstants>(&mut s);
    declare::<FxaaConstants>(&mut s);
    declare::<ProbeConstants>(&mut s);
    declare::<EnvironmentHeader>(&mut s);
    declare::<EnvironmentCell>(&mut s);
    for (name, v) in [
        ("LIGHT_POINT", LightKinds::POINT),
        ("LIGHT_SPOT", LightKinds::SPOT),
        ("LIGHT_DIRECTIONAL", LightKinds::DIRECTIONAL),
        ("LIGHT_RECT", LightKinds::RECT),
        ("PHASE_HENYEY_GREENSTEIN", Phases::HENYEY_GREENSTEIN),
        ("PHASE_RAYLEIGH", Phases::RAYLEIGH),
        ("SHADOW_ORTHOGRAPHIC", ShadowKinds::ORTHOGRAPHIC),
        ("SHADOW_PERSPECTIVE", ShadowKinds::PERSPECTIVE),
        ("SHADOW_CUBE", ShadowKinds::CUBE),
        ("FRAME_SHADOW_MAPS", FrameFlags::SHADOW_MAPS),
        ("FRAME_RT_SHADOWS", FrameFlags::RT_SHADOWS),
        ("FRAME_RT_AO", FrameFlags::RT_AO),
        ("FRAME_RT_REFLECTIONS", FrameFlags::RT_REFLECTIONS),
        ("FRAME_REFLECTIONS_HALF", FrameFlags::REFLECTIONS_HALF),
        ("FRAME_RT_GI", FrameFlags::RT_GI),
        ("FRAME_SCREEN_GI", FrameFlags::SCREEN_GI),
        ("FRAME_SCREEN_REFLECTIONS", FrameFlags::SCREEN_REFLECTIONS),
        ("FRAME_RT_DIRECT", FrameFlags::RT_DIRECT),
        ("FRAME_PROBE_SPECULAR", FrameFlags::PROBE_SPECULAR),
        ("MATERIAL_DOUBLE_SIDED", crate::sections::MaterialFlags::DOUBLE_SIDED),
        ("MATERIAL_ALPHA_SHIFT", crate::sections::MaterialFlags::ALPHA_MODE_SHIFT),
        ("MATERIAL_DIFFUSE_ONLY", crate::sections::MaterialFlags::DIFFUSE_ONLY),
        ("MATERIAL_SPECULAR", crate::sections::MaterialFlags::SPECULAR),
        ("NO_TEXTURE", crate::sections::NO_TEXTURE),
        ("EMITTER_LIGHT", EmitterKinds::LIGHT),
        ("EMITTER_TRIANGLE", EmitterKinds::TRIANGLE),
        ("EMISSIVE_DOUBLE_SIDED", EmissiveFlags::DOUBLE_SIDED),
        ("EMISSIVE_TEXTURED", EmissiveFlags::TEXTURED),
        ("EMISSIVE_TRIANGLE_MASK", EmissiveFlags::TRIANGLE_MASK),
        ("TEXTURE_WRAP_U_SHIFT", TextureFlags::WRAP_U_SHIFT),
        ("TEXTURE_WRAP_V_SHIFT", TextureFlags::WRAP_V_SHIFT),
        ("TEXTURE_SRGB", TextureFlags::SRGB),
        ("TEXTURE_LINEAR", TextureFlags::LINEAR),
        ("TEXTURE_LEVELS_SHIFT", TextureFlags::LEVELS_SHIFT),
        ("TEXTURE_FORMAT_SHIFT", TextureFlags::FORMAT_SHIFT),
        ("TEXTURE_SWIZZLE_SHIFT", TextureFlags::SWIZZLE_SHIFT),
        ("MAX_SHADOW_MAPS", MAX_SHADOW_MAPS as u32),
        ("MAX_RT_SHADOW_LIGHTS", MAX_RT_SHADOW_LIGHTS as u32),
        ("REFLECTION_SECOND_HIT_LIGHTS", REFLECTION_SECOND_HIT_LIGHTS as u32),
    ] {
        s.push_str(&format!("const uint {name} = {v}u;\n"));
    }
    s.push_str("\n#endif\n");
    s
}

gpu_struct! {
    /// The voxel grid and line space as the player's queries read them (`shaders/common/
    /// linespace.glsl`; uniform, std140, 128 bytes). The arrays the chosen techniques need are
    /// concatenated into one space of 32-bit words, split into storage buffers ("chunks") of
    /// `1 << chunk_shift` words each, so that no buffer exceeds the device's
    /// `maxStorageBufferRange`; each array's first word in that space is a `*_base` field
    /// (`u32::MAX` for an array not uploaded).
    pub struct GpuGrid {
        /// Minimum corner of the grid: the file's f64 origin rounded to f32 …
        pub origin: [f32; 3] => "vec3",
        /// Cell edge length.
        pub cell: f32 => "float",
        /// … and what the rounding lost (origin − `origin` in f64, rounded): grid coordinates
        /// are `((p − origin) − origin_lo) / cell`, exact to a few ulps of the cell even 1e5 from
        /// the world's origin, where `origin` alone is off by up to 4e-3.
        pub origin_lo: [f32; 3] => "vec3",
        /// 1 / cell.
        pub inv_cell: f32 => "float",
        /// Cells along x, y, z.
        pub dims: [u32; 3] => "uvec3",
        /// Shaft resolution N (0 without line space).
        pub shaft_res: u32 => "uint",
        /// The grid margin (scene units): how far cells and shafts were widened.
        pub margin: f32 => "float",
        /// Shaft-bit words per slot.
        pub words_per_slot: u32 => "uint",
        /// `Variants` present in the file.
        pub variants: u32 => "uint",
        /// Slack of the candidate lists' early exit, in cell units (see `query.rs`), widened for
        /// single-precision key evaluation.
        pub key_eps: f32 => "float",
        /// PNMT self-hit distance: a record must lie further than this in front of the origin's
        /// surface (the position quantisation step plus the margin).
        pub pnmt_step: f32 => "float",
        /// log2 of the words per chunk.
        pub chunk_shift: u32 => "uint",
        /// How PNMT records are stored (`PnmtLayout` code).
        pub pnmt_layout: u32 => "uint",
        /// Zero.
        pub reserved: u32 => "uint",
        /// First word of: cell triangle offsets, cell triangle lists, slots, shaft bits.
        pub bases_a: [u32; 4] => "uvec4",
        /// First word of: shaft ranks, candidate offsets, candidate entries, PNMT records.
        pub bases_b: [u32; 4] => "uvec4",
        /// First word of: pre-illuminated records; then three zeros.
        pub bases_c: [u32; 4] => "uvec4",
    }
}

gpu_struct! {
    /// The GLSL view of [`crate::sections::GpuMaterial`] (same bytes; std430, 80 bytes).
    pub struct GpuMaterialLayout {
        /// See `GpuMaterial`.
        pub base_color: [f32; 4] => "vec4",
        /// See `GpuMaterial`.
        pub emission: [f32; 3] => "vec3",
        /// See `GpuMaterial`.
        pub metallic: f32 => "float",
        /// See `GpuMaterial`.
        pub roughness: f32 => "float",
        /// See `GpuMaterial`.
        pub alpha_cutoff: f32 => "float",
        /// See `GpuMaterial`.
        pub normal_scale: f32 => "float",
        /// See `GpuMaterial`.
        pub occlusion_strength: f32 => "float",
        /// See `GpuMaterial`.
        pub base_color_texture: u32 => "uint",
        /// See `GpuMaterial`.
        pub metallic_roughness_texture: u32 => "uint",
        /// See `GpuMaterial`.
        pub normal_texture: u32 => "uint",
        /// See `GpuMaterial`.
        pub occlusion_texture: u32 => "uint",
        /// See `GpuMaterial`.
        pub emissive_texture: u32 => "uint",
        /// See `GpuMaterial`.
        pub flags: u32 => "uint",
        /// See `GpuMaterial` (four halves: `dielectric_f0`, `dielectric_f90` in `scene.glsl`).
        pub specular: [u32; 2] => "uvec2",
        /// See `GpuMaterial`.
        pub clearcoat: f32 => "float",
        /// See `GpuMaterial`.
        pub clearcoat_roughness: f32 => "float",
        /// See `GpuMaterial`.
        pub clearcoat_texture: u32 => "uint",
        /// See `GpuMaterial`.
        pub clearcoat_roughness_texture: u32 => "uint",
        /// See `GpuMaterial`.
        pub transmission: f32 => "float",
        /// See `GpuMaterial`.
        pub transmission_texture: u32 => "uint",
        /// See `GpuMaterial` (zero).
        pub reserved: [u32; 2] => "uvec2",
    }
}

/// Asserts that the committed file at `path` (relative to the workspace root) is exactly `text`,
/// a GLSL mirror generated from this crate; with `KILN_BLESS` set it writes `text` there first.
/// `filter` is the test-name filter the message suggests for regenerating.
#[cfg(test)]
pub(crate) fn assert_committed(path: &str, text: &str, filter: &str) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path);
    if std::env::var_os("KILN_BLESS").is_some() {
        std::fs::write(&path, text).expect("write the generated file");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == text,
        "{} differs from the generated text; run KILN_BLESS=1 cargo test -p kiln-format {filter}",
        path.display()
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check<T: GlslStruct>() {
        let (offsets, size) = glsl_offsets::<T>();
        for ((name, ty, rust, _), glsl) in T::fields().into_iter().zip(offsets) {
            assert_eq!(rust, glsl, "{}.{name} ({ty}): Rust offset {rust}, GLSL offset {glsl}", T::NAME);
        }
        assert_eq!(T::size(), size, "{}: Rust size {}, GLSL size {size}", T::NAME, T::size());
    }

    #[test]
    fn rust_and_glsl_layouts_agree() {
        check::<EnvironmentHeader>();
        check::<EnvironmentCell>();
        check::<GpuLight>();
        check::<GpuShadow>();
        check::<FrameConstants>();
        check::<GpuMaterialLayout>();
        check::<ReferenceConstants>();
        check::<GpuEmitter>();
        check::<GpuEmissive>();
        check::<GpuMedium>();
        check::<GpuTexture>();
        check::<GpuVertexAttributes>();
        check::<RtConstants>();
        check::<MarchConstants>();
        check::<GodRayConstants>();
        check::<TothConstants>();
        check::<ScreenAoConstants>();
        check::<SsrConstants>();
        check::<DenoiseConstants>();
        check::<ProbeConstants>();
        check::<GpuGrid>();
        check::<BakeParams>();
        check::<BakeCell>();
        // The material section and its GLSL view are the same bytes.
        let m = crate::sections::GpuMaterial {
            base_color_texture: 3,
            flags: 5,
            metallic: 0.25,
            ..Default::default()
        };
        let v: GpuMaterialLayout = bytemuck::cast(m);
        assert_eq!((v.base_color_texture, v.flags, v.metallic), (3, 5, 0.25));
    }

    /// `shaders/common/layout.glsl` must be exactly the generated text
    /// (`KILN_BLESS=1 cargo test -p kiln-format layout` regenerates it).
    #[test]
    fn committed_bake_layout_is_generated() {
        assert_committed("compiler/shaders/bake_layout.glsl", &bake_layout(), "bake_layout");
    }

    #[test]
    fn committed_glsl_layout_is_generated() {
        assert_committed("shaders/common/layout.glsl", &glsl_layout(), "layout");
    }
}
