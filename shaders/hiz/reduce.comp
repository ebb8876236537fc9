#version 460
// Level `level` of the Hi-Z pyramid from the level below: the closest surface (largest
// reversed-Z depth) of the 2 × 2 children, a conservative bound: no surface of a cell is nearer
// the camera than the cell's value, so a ray in front of it crosses nothing there. Levels halve
// rounding up, so that a child's parent is always (child / 2): the last texel of an odd-sized
// level has one child, or two, and reads only those.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) uniform image2D hiz;
layout(push_constant) uniform Push { SsrConstants ssr; };

#include "../common/screen_ao.glsl"

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    int level = int(ssr.level);
    if (any(greaterThanEqual(q, pyramid_size(level)))) {
        return;
    }
    ivec2 below = pyramid_size(level - 1);
    ivec2 origin = pyramid_origin(level - 1);
    float closest = 0.0;
    for (int j = 0; j < 2; j++) {
        for (int i = 0; i < 2; i++) {
            ivec2 c = 2 * q + ivec2(i, j);
            if (all(lessThan(c, below))) {
                closest = max(closest, imageLoad(hiz, origin + c).r);
            }
        }
    }
    imageStore(hiz, pyramid_origin(level) + q, vec4(closest));
}
