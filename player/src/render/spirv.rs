//! SPIR-V of every shader, built from `shaders/` by `shaders/build.sh` (checked by
//! `player/tests/spirv.rs`). A shader's SPIR-V is named by its path under `shaders/`:
//! `rt/ao.comp` is `shaders/spirv/rt.ao.comp.spv`. Each entry names the source once, as
//! `"folder" / "file"`, and the macro spells both the embedded file and [`ALL`]'s source path from
//! it, so the table cannot name one source and embed another's bytes.

macro_rules! shaders {
    ($($(#[$doc:meta])* $name:ident = $folder:literal / $file:literal;)*) => {
        $(
            $(#[$doc])*
            pub const $name: &[u8] =
                include_bytes!(concat!("../../../shaders/spirv/", $folder, ".", $file, ".spv"));
        )*
        /// (source under `shaders/`, embedded bytes) of every shader.
        pub const ALL: &[(&str, &[u8])] = &[$((concat!($folder, "/", $file), $name),)*];
    };
}

shaders! {
    /// G-buffer vertex shader.
    GBUFFER_VERT = "gbuffer" / "gbuffer.vert";
    /// G-buffer fragment shader.
    GBUFFER_FRAG = "gbuffer" / "gbuffer.frag";
    /// Direct light.
    DIRECT = "lighting" / "direct.comp";
    /// Tone mapping.
    TONEMAP = "post" / "tonemap.comp";
    /// Temporal anti-aliasing.
    TAA_RESOLVE = "taa" / "resolve.comp";
    /// Temporal anti-aliasing: the history written over the radiance.
    TAA_OUTPUT = "taa" / "output.comp";
    /// Reprojected accumulation: where each pixel's point was, its frames of history.
    HISTORY_MOTION = "history" / "motion.comp";
    /// Reprojected accumulation of a layered one-channel target (shadows).
    HISTORY_BLEND_LAYERS = "history" / "blend_layers.comp";
    /// Reprojected accumulation of a one-channel target (AO).
    HISTORY_BLEND_R = "history" / "blend_r.comp";
    /// Reprojected accumulation of a four-channel target (reflections, GI).
    HISTORY_BLEND_RGBA = "history" / "blend_rgba.comp";
    /// Participating media by ray marching.
    MEDIA_MARCH = "media" / "march.comp";
    /// Mitchell's occlusion image.
    MITCHELL_OCCLUSION = "mitchell" / "occlusion.comp";
    /// Mitchell's radial blur.
    MITCHELL_BLUR = "mitchell" / "blur.comp";
    /// Sousa's depth map.
    SOUSA_DEPTH = "sousa" / "depth.comp";
    /// Sousa's first two radial blurs.
    SOUSA_BLUR = "sousa" / "blur.comp";
    /// Sousa's last radial blur, added to the radiance.
    SOUSA_COMPOSITE = "sousa" / "composite.comp";
    /// Level 0 of the camera-space depth pyramid.
    PYRAMID_LINEAR = "pyramid" / "linear.comp";
    /// Levels 0 to 5 of a nearest depth pyramid in one dispatch.
    PYRAMID_SINGLE = "pyramid" / "single.comp";
    /// A level of the depth pyramid from the one below.
    PYRAMID_REDUCE = "pyramid" / "reduce.comp";
    /// Level 0 of the Hi-Z pyramid of the screen-space reflections.
    HIZ_COPY = "hiz" / "copy.comp";
    /// A level of the Hi-Z pyramid from the one below (closest surface).
    HIZ_REDUCE = "hiz" / "reduce.comp";
    /// Screen-space reflections: the hierarchical march.
    SSR_TRACE = "ssr" / "trace.comp";
    /// Level 0 of the lit-radiance pyramid: the previous frame's light, reprojected.
    LIT_REPROJECT = "lit" / "reproject.comp";
    /// A level of the lit-radiance pyramid from the one below.
    LIT_REDUCE = "lit" / "reduce.comp";
    /// Screen-space GI: depth, normal and light packed into one texel.
    SSGI_PACK = "ssgi" / "pack.comp";
    /// Screen-space GI: one level's gather plus the coarser levels upsampled.
    SSGI_GATHER = "ssgi" / "gather.comp";
    /// Screen-space GI: the finest level upsampled to the screen, averaged over frames.
    SSGI_RESOLVE = "ssgi" / "resolve.comp";
    /// Scalable ambient obscurance (the seed's).
    SAO = "sao" / "sao.comp";
    /// Ground-truth ambient occlusion.
    GTAO = "gtao" / "gtao.comp";
    /// The screen-space AO's depth-aware blur and upsampling.
    AO_BLUR = "ao" / "blur.comp";
    /// Tóth & Umenhoffer's shadow-map ray march.
    TOTH_MARCH = "toth" / "march.comp";
    /// The blur that joins Tóth's interleaved samples.
    TOTH_BLUR = "toth" / "blur.comp";
    /// Ray queries from a buffer.
    TRACE_RAYS = "trace" / "rays.comp";
    /// Line-space queries from a buffer.
    TRACE_LINESPACE = "trace" / "linespace.comp";
    /// Visibility-buffer raster pass.
    VISIBILITY_FRAG = "gbuffer" / "visibility.frag";
    /// Visibility-buffer raster pass for opaque one-sided materials.
    VISIBILITY_OPAQUE_FRAG = "gbuffer" / "visibility_opaque.frag";
    /// Visibility-buffer resolve.
    RESOLVE = "gbuffer" / "resolve.comp";
    /// The reference path tracer.
    PATHTRACE = "reference" / "pathtrace.comp";
    /// Ray-traced soft shadows.
    RT_SHADOWS = "rt" / "shadows.comp";
    /// Soft shadows by line-space feelers, exact in the end cells.
    RT_SHADOWS_LINESPACE = "rt" / "shadows_linespace.comp";
    /// Soft shadows by line-space feelers, exact in filled shafts.
    RT_SHADOWS_LINESPACE_EXACT = "rt" / "shadows_linespace_exact.comp";
    /// Ray-traced ambient occlusion.
    RT_AO = "rt" / "ao.comp";
    /// Ray-traced glossy reflections.
    RT_REFLECTIONS = "rt" / "reflections.comp";
    /// Diffuse global illumination, its rays through the CWBVH.
    RT_GI = "rt" / "gi.comp";
    /// Diffuse GI through the line space: PNMT bounce hits.
    RT_GI_LINESPACE_PNMT = "rt" / "gi_linespace_pnmt.comp";
    /// Diffuse GI through the line space: candidate-list bounce hits.
    RT_GI_LINESPACE_CANDIDATES = "rt" / "gi_linespace_candidates.comp";
    /// Diffuse GI through the line space: pre-illuminated records.
    RT_GI_LINESPACE_PREILLUM = "rt" / "gi_linespace_preillum.comp";
    /// Shadow rays at the reflection hits.
    RT_REFLECTION_SHADOWS = "rt" / "reflection_shadows.comp";
    /// Ray generation of the driver-pipeline peer: one ray of the buffer per launch index.
    PEER_RGEN = "peer" / "trace.rgen";
    /// Miss shader of the peer: no hit.
    PEER_RMISS = "peer" / "trace.rmiss";
    /// Closest-hit shader of the peer: distance, primitive, barycentrics.
    PEER_RCHIT = "peer" / "trace.rchit";
}
