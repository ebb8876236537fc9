#version 460
// Level 0 of the Hi-Z pyramid: the G-buffer's reversed-Z depth as it is (0 where the sky shows).
// Depth, not camera distance: a perspective ray is a straight line in (image x, image y, depth),
// so the march steps it linearly (shaders/ssr/trace.comp).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2, r32f) uniform writeonly image2D hiz;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), frame.size.xy))) {
        return;
    }
    imageStore(hiz, p, vec4(texelFetch(depth_tex, p, 0).r));
}
