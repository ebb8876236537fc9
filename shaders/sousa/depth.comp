#version 460
// Sousa's depth map (`--media sousa`, seed 002 §6, pass 1) at a fraction of the screen's
// resolution: the view distance over `gc.extent` (the distance across the scene from the
// camera), clamped to 1, and 1 for the sky. Large depth is bright: the method assumes the light
// lies far away, behind everything (its known failure otherwise, the seed's Fig. 3.8).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D g_depth;
layout(set = 0, binding = 2, r16f) uniform writeonly image2D depth_map;
layout(push_constant) uniform Push { GodRayConstants gc; };

#include "../common/pixel.glsl"

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(depth_map);
    if (any(greaterThanEqual(texel, size))) {
        return;
    }
    vec2 at = (vec2(texel) + 0.5) * vec2(frame.size.xy) / vec2(size);
    ivec2 pixel = min(ivec2(at), ivec2(frame.size.xy) - 1);
    vec3 o = pixel_origin(at);
    vec3 d = normalize(pixel_ray(at));
    float t = surface_distance(at, texelFetch(g_depth, pixel, 0).r, o, d);
    imageStore(depth_map, texel, vec4(t == SKY_DISTANCE ? 1.0 : min(t / gc.extent, 1.0)));
}
