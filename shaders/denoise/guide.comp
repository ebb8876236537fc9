#version 460
// The denoiser, step 1 (svgf.glsl): each pixel's distance along its camera ray (from the
// G-buffer's reversed-Z depth) and normal, packed for the filter's taps.
layout(set = 0, binding = 1) uniform sampler2D g_depth;
layout(set = 0, binding = 2) uniform sampler2D g_normal;
layout(set = 0, binding = 3, rg32ui) uniform writeonly uimage2D guide;

#include "svgf.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    float depth = texelFetch(g_depth, pixel, 0).r;
    vec2 at = vec2(pixel) + 0.5;
    vec3 ray = pixel_ray(at);
    // The distance in units of the (unnormalised) ray: the point is origin + ray · t.
    float t = dot(world_at_depth(at, depth) - pixel_origin(at), ray) / dot(ray, ray);
    if (!(depth > 0.0) || isnan(t) || isinf(t)) {
        imageStore(guide, pixel, uvec4(GUIDE_SKY));
        return;
    }
    vec2 n = texelFetch(g_normal, pixel, 0).rg;
    imageStore(guide, pixel, uvec4(floatBitsToUint(t), packSnorm2x16(n), 0u, 0u));
}
