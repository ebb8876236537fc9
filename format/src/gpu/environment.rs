//! The environment's header and sampling-table cell (FORMAT.md, "Environment"): section layouts
//! the shaders read as they are (`crate::environment` has the rest).

use bytemuck::{Pod, Zeroable};

use super::GlslStruct;

gpu_struct! {
    /// The environment's header (`ENVH`, one element, 192 bytes), as the shaders read it too.
    pub struct EnvironmentHeader {
        /// Radiance map (`ENVR`) width and height (width = 2 × height), then two zeros.
        pub map: [u32; 4] => "uvec4",
        /// Prefiltered level 0 width and height, the level count, and the index of level 0's first
        /// texel in the shaders' texel array (= the radiance map's texel count).
        pub filtered: [u32; 4] => "uvec4",
        /// Sampling table (`ENVT`) width and height (width = 2 × height), then two zeros.
        pub table: [u32; 4] => "uvec4",
        /// Irradiance over π as real spherical harmonics up to band 2 (rgb; w zero), convolved
        /// with the clamped cosine: evaluated at a unit normal n with [`sh_basis`] they give the
        /// mean radiance over the cosine-weighted hemisphere around n (a Lambertian surface of
        /// albedo a reflects a times that).
        pub sh: [[f32; 4]; 9] => "vec4[9]",
    }
}

gpu_struct! {
    /// One cell of the sampling table (`ENVT`, 16 bytes): an alias-table entry over the cells,
    /// which are drawn in proportion to their mean luminance times their solid angle.
    pub struct EnvironmentCell {
        /// A draw landing on this cell keeps it when its second uniform is below this.
        pub keep: f32 => "float",
        /// The cell taken otherwise.
        pub alias: u32 => "uint",
        /// This cell's probability times (cells / 2π²): a direction in the cell has solid-angle
        /// density `density / sin θ`.
        pub density: f32 => "float",
        /// The alias cell's `density`.
        pub alias_density: f32 => "float",
    }
}
