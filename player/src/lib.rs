//! kiln-play: streams a `.kiln` file to the GPU and renders it with Vulkan, headless or in a
//! window.
//!
//! Layers, bottom up: [`gpu`] (the only module that speaks raw Vulkan), [`scene`] (streaming
//! upload of a file's sections), [`render`] (passes and their targets), and the front ends
//! [`headless`], [`window`] and [`bench`], driven by [`cli`]; [`sweep`] is `kiln-bench`.

pub mod bench;
pub mod camera;
pub mod cli;
pub mod error;
pub mod gpu;
pub mod headless;
pub mod image_out;
pub mod peer;
pub mod raybench;
pub mod reference;
pub mod render;
pub mod scene;
pub mod session;
pub mod sweep;
pub mod trace;
pub mod trace_linespace;
pub mod window;

pub use error::{Exit, PlayError, PlayResult};
