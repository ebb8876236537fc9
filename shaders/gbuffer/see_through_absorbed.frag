#version 460
// The see-through layer's absorption (passes/see_through.rs): over every see-through surface in
// front of the opaque G-buffer's, what each lets through of the light from straight behind it,
// summed as −ln (`gbuffer.glsl`).
#define SEE_THROUGH
#define SEE_THROUGH_ABSORBED
#include "gbuffer.glsl"
