#version 460
// Four channels (the ray-traced reflections and GI): see blend.glsl.
#define FORMAT rgba32f
#include "blend.glsl"
