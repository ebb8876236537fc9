#version 460
// Direct light of emissive surfaces, second kernel (`direct.glsl`): neighbours' reservoirs
// joined, the survivor's shadow ray, the pixel shaded and its reservoir kept for the next frame.
#include "hybrid.glsl"
#include "direct.glsl"

void main() {
    reuse_main();
}
