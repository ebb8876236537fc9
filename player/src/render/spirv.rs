//! SPIR-V of every shader, built from `shaders/` by `shaders/build.sh` (checked by a test).

/// G-buffer vertex shader.
pub const GBUFFER_VERT: &[u8] = include_bytes!("../../../shaders/spirv/gbuffer.vert.spv");
/// G-buffer fragment shader.
pub const GBUFFER_FRAG: &[u8] = include_bytes!("../../../shaders/spirv/gbuffer.frag.spv");
/// Direct light.
pub const DIRECT: &[u8] = include_bytes!("../../../shaders/spirv/direct.comp.spv");
/// Tone mapping.
pub const TONEMAP: &[u8] = include_bytes!("../../../shaders/spirv/tonemap.comp.spv");
/// Ray queries from a buffer.
pub const TRACE_RAYS: &[u8] = include_bytes!("../../../shaders/spirv/rays.comp.spv");
/// Visibility-buffer raster pass.
pub const VISIBILITY_FRAG: &[u8] = include_bytes!("../../../shaders/spirv/visibility.frag.spv");
/// Visibility-buffer raster pass for opaque one-sided materials.
pub const VISIBILITY_OPAQUE_FRAG: &[u8] = include_bytes!("../../../shaders/spirv/visibility_opaque.frag.spv");
/// Visibility-buffer resolve.
pub const RESOLVE: &[u8] = include_bytes!("../../../shaders/spirv/resolve.comp.spv");
/// The reference path tracer.
pub const PATHTRACE: &[u8] = include_bytes!("../../../shaders/spirv/pathtrace.comp.spv");
/// Ray-traced soft shadows.
pub const RT_SHADOWS: &[u8] = include_bytes!("../../../shaders/spirv/shadows.comp.spv");
/// Ray-traced ambient occlusion.
pub const RT_AO: &[u8] = include_bytes!("../../../shaders/spirv/ao.comp.spv");
/// Ray-traced glossy reflections.
pub const RT_REFLECTIONS: &[u8] = include_bytes!("../../../shaders/spirv/reflections.comp.spv");
/// Shadow rays at the reflection hits.
pub const RT_REFLECTION_SHADOWS: &[u8] = include_bytes!("../../../shaders/spirv/reflection_shadows.comp.spv");
/// Ray generation of the driver-pipeline peer: one ray of the buffer per launch index.
pub const PEER_RGEN: &[u8] = include_bytes!("../../../shaders/spirv/trace.rgen.spv");
/// Miss shader of the peer: no hit.
pub const PEER_RMISS: &[u8] = include_bytes!("../../../shaders/spirv/trace.rmiss.spv");
/// Closest-hit shader of the peer: distance, primitive, barycentrics.
pub const PEER_RCHIT: &[u8] = include_bytes!("../../../shaders/spirv/trace.rchit.spv");
/// (source under `shaders/`, embedded bytes) of every shader.
pub const ALL: [(&str, &[u8]); 16] = [
    ("gbuffer/gbuffer.vert", GBUFFER_VERT),
    ("gbuffer/gbuffer.frag", GBUFFER_FRAG),
    ("lighting/direct.comp", DIRECT),
    ("post/tonemap.comp", TONEMAP),
    ("trace/rays.comp", TRACE_RAYS),
    ("reference/pathtrace.comp", PATHTRACE),
    ("rt/shadows.comp", RT_SHADOWS),
    ("rt/ao.comp", RT_AO),
    ("rt/reflections.comp", RT_REFLECTIONS),
    ("rt/reflection_shadows.comp", RT_REFLECTION_SHADOWS),
    ("gbuffer/visibility.frag", VISIBILITY_FRAG),
    ("gbuffer/visibility_opaque.frag", VISIBILITY_OPAQUE_FRAG),
    ("gbuffer/resolve.comp", RESOLVE),
    ("peer/trace.rgen", PEER_RGEN),
    ("peer/trace.rmiss", PEER_RMISS),
    ("peer/trace.rchit", PEER_RCHIT),
];
