#version 460
// atrous.glsl with SVGF's 5 × 5 taps (the B3 spline).
#define RADIUS 2
#include "atrous.glsl"
