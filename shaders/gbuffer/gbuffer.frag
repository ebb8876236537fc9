#version 460
// G-buffer pass: material evaluation into five targets (`gbuffer.glsl` says which) for the
// opaque surfaces, and for every surface where the scene has nothing see-through.
#include "gbuffer.glsl"
