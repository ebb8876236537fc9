#version 460
// The denoiser, step 1 (svgf.glsl): each pixel's camera-relative position (from the G-buffer's
// reversed-Z depth) and normal, packed for the filter's taps.
layout(set = 0, binding = 1) uniform sampler2D g_depth;
layout(set = 0, binding = 2) uniform sampler2D g_normal;
layout(set = 0, binding = 3, rgba32ui) uniform writeonly uimage2D guide;

#include "svgf.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    float depth = texelFetch(g_depth, pixel, 0).r;
    vec3 p = world_at_depth(vec2(pixel) + 0.5, depth) - frame.camera.xyz;
    if (!(depth > 0.0) || any(isnan(p)) || any(isinf(p))) {
        imageStore(guide, pixel, uvec4(GUIDE_SKY));
        return;
    }
    vec2 n = texelFetch(g_normal, pixel, 0).rg;
    imageStore(guide, pixel, uvec4(floatBitsToUint(p), packSnorm2x16(n)));
}
