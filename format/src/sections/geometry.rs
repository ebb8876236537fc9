//! Vertex layout shared with the player's shaders.

use bytemuck::{Pod, Zeroable};

/// A world-space vertex. 24 bytes, no padding; GLSL reads it as 6 floats. Texture
/// coordinates are a separate stream (`UVS0`), present only when a material samples a texture.
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
#[repr(C)]
pub struct Vertex {
    /// Position in scene units.
    pub position: [f32; 3],
    /// Unit shading normal.
    pub normal: [f32; 3],
}

const _: () = assert!(size_of::<Vertex>() == 24);
