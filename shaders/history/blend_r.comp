#version 460
// One channel (the ray-traced AO): see blend.glsl.
#define FORMAT r32f
#include "blend.glsl"
