#version 460
// Temporal anti-aliasing, last step: the history the resolve just wrote (half floats) into the
// radiance image (32-bit floats), which tone mapping, read-back and the next frame's lit pyramid
// read. Alpha carries the history length, as the history's.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D history;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D radiance;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    imageStore(radiance, pixel, imageLoad(history, pixel));
}
