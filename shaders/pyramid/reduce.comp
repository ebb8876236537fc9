#version 460
// Level `level` of the depth pyramid from the level below: nearest, one of each 2 × 2 block's
// depths copied unchanged (never an average, which would invent depths between surfaces), the
// child picked on McGuire et al.'s rotated grid (2012, §2.2) so that successive levels do not
// all keep the same corner.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) uniform image2D pyramid;
layout(push_constant) uniform Push { ScreenAoConstants ao; };

#include "../common/screen_ao.glsl"

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    int level = int(ao.level);
    if (any(greaterThanEqual(q, pyramid_size(level)))) {
        return;
    }
    ivec2 child = min(2 * q + ivec2((q.y & 1) ^ 1, (q.x & 1) ^ 1), pyramid_size(level - 1) - 1);
    float z = imageLoad(pyramid, pyramid_origin(level - 1) + child).r;
    imageStore(pyramid, pyramid_origin(level) + q, vec4(z));
}
