//! Vertex layout shared with the player's shaders.

use bytemuck::{Pod, Zeroable};

/// A world-space vertex. 32 bytes, no padding; GLSL reads it as 8 floats.
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
#[repr(C)]
pub struct Vertex {
    /// Position in scene units.
    pub position: [f32; 3],
    /// Unit shading normal.
    pub normal: [f32; 3],
    /// Texture coordinate set 0 (glTF convention: v points down the image).
    pub uv: [f32; 2],
}

const _: () = assert!(size_of::<Vertex>() == 32);
