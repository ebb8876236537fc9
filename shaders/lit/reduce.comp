#version 460
// Level `level` of the lit-radiance pyramid from the level below: the mean of each 2 × 2 block's
// lit texels (the seed blits with linear filtering), alpha the fraction of them that were lit,
// so that the sky and missing history do not darken the light that is there.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, rgba16f) uniform image2D lit;
layout(push_constant) uniform Push { ScreenGiConstants gi; };

#include "../common/screen_ao.glsl"

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    int level = int(gi.level);
    if (any(greaterThanEqual(q, pyramid_size(level)))) {
        return;
    }
    ivec2 below = pyramid_size(level - 1);
    ivec2 origin = pyramid_origin(level - 1);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int i = 0; i < 4; i++) {
        ivec2 c = min(2 * q + ivec2(i & 1, i >> 1), below - 1);
        vec4 l = imageLoad(lit, origin + c);
        sum += l.rgb * l.a;
        weight += l.a;
    }
    imageStore(lit, pyramid_origin(level) + q, weight > 0.0 ? vec4(sum / weight, weight * 0.25) : vec4(0.0));
}
