#version 460
// atrous.glsl with 3 × 3 taps (the linear B-spline): 9 taps an iteration instead of 25.
#define RADIUS 1
#include "atrous.glsl"
