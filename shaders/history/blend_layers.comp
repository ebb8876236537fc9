#version 460
// One layer per light (the ray-traced shadows): see blend.glsl.
#define LAYERED
#define FORMAT r32f
#include "blend.glsl"
