#version 460
// Line-space shadow feelers, exact in every filled shaft (shadows_linespace.glsl).
#define SHADOW_LS_EXACT true
#include "shadows_linespace.glsl"
