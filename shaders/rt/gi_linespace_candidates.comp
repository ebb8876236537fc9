#version 460
// Diffuse GI (gi.glsl) through the line space, structure candidates (see gi_linespace.glsl).
#define GI_LS_STRUCTURE GI_LS_CANDIDATES
#include "gi_linespace.glsl"

void main() {
    gi_main();
}
