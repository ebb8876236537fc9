#version 460
// The see-through layer (passes/see_through.rs): the nearest see-through surface (blended or
// transmitting) in front of the opaque G-buffer's, into targets of its own: the G-buffer's five
// and the coverage (`gbuffer.glsl`).
#define SEE_THROUGH
#include "gbuffer.glsl"
