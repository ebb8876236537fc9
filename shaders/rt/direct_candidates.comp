#version 460
// Direct light of emissive surfaces, first kernel (`direct.glsl`): each pixel's candidates, their
// visibility when reservoirs are reused, and the previous frame's reservoir joined to them.
#include "hybrid.glsl"
#include "direct.glsl"

void main() {
    candidates_main();
}
