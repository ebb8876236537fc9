#version 460
// Line-space shadow feelers, exact near their ends (shadows_linespace.glsl).
#define SHADOW_LS_EXACT false
#include "shadows_linespace.glsl"
