//! The emitter tables of next-event estimation and of the direct light of emissive surfaces,
//! and the power they weigh emitters by (the compiler's `kiln plan` reports the same).

use bytemuck::{Pod, Zeroable};

use super::GlslStruct;

/// Luminance (Rec. 709 weights) of a linear colour: what the emitter tables weigh emission by.
pub fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// Emitted power, up to a common constant, of a Lambertian emitter of radiance `emission` and
/// `area`: π · luminance · area, what an emissive triangle is chosen in proportion to.
pub fn emitted_power(emission: [f32; 3], area: f32) -> f32 {
    std::f32::consts::PI * luminance(emission) * area
}

gpu_struct! {
    /// One entry of the emitter table of next-event estimation (std430, 20 bytes): emitters are
    /// chosen with probability proportional to their power, in O(1) by Walker's alias method
    /// (entry i = ⌊ξ·N⌋ kept with probability `keep`, else `alias`; a search of cumulative
    /// probabilities took 17 dependent reads per vertex over ToyCar's 88,837 emitters).
    pub struct GpuEmitter {
        /// [`EmitterKinds`].
        pub kind: u32 => "uint",
        /// Light index (analytic) or triangle (leaf order).
        pub index: u32 => "uint",
        /// Probability that a draw landing on this entry keeps it.
        pub keep: f32 => "float",
        /// Selection probability of this entry.
        pub pdf: f32 => "float",
        /// The entry a draw that does not keep this one takes.
        pub alias: u32 => "uint",
    }
}

gpu_struct! {
    /// One emissive triangle as the direct light of emissive surfaces draws it (std430, 64
    /// bytes): everything a candidate reads in one place (the path tracer's table reaches the
    /// triangle and its material through two more lookups), chosen in O(1) by Walker's alias
    /// method as [`GpuEmitter`]s are.
    pub struct GpuEmissive {
        /// First corner.
        pub p0: [f32; 3] => "vec3",
        /// Probability of choosing this triangle (proportional to its power).
        pub pdf: f32 => "float",
        /// Second corner minus the first.
        pub e1: [f32; 3] => "vec3",
        /// Probability that a draw landing on this entry keeps it.
        pub keep: f32 => "float",
        /// Third corner minus the first.
        pub e2: [f32; 3] => "vec3",
        /// The entry a draw that does not keep this one takes.
        pub alias: u32 => "uint",
        /// The material's emission (linear), before its emissive texture.
        pub emission: [f32; 3] => "vec3",
        /// The triangle (leaf order) in bits 0–29; [`EmissiveFlags`] above.
        pub triangle: u32 => "uint",
    }
}

/// Flags in [`GpuEmissive::triangle`]'s top bits.
#[derive(Debug)]
pub struct EmissiveFlags;

impl EmissiveFlags {
    /// The material emits from both sides.
    pub const DOUBLE_SIDED: u32 = 1 << 31;
    /// The material has an emissive texture (read through the triangle's material).
    pub const TEXTURED: u32 = 1 << 30;
    /// The bits holding the triangle.
    pub const TRIANGLE_MASK: u32 = (1 << 30) - 1;
}

/// Kinds in [`GpuEmitter::kind`].
#[derive(Debug)]
pub struct EmitterKinds;

impl EmitterKinds {
    /// An analytic light of the manifest.
    pub const LIGHT: u32 = 0;
    /// An emissive triangle.
    pub const TRIANGLE: u32 = 1;
}
