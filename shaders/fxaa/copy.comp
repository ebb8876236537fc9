#version 460
// Fast approximate anti-aliasing, last step: the smoothed image back into the radiance image,
// which tone mapping, read-back and the next frame's lit pyramid read.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D smoothed;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D radiance;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    imageStore(radiance, pixel, imageLoad(smoothed, pixel));
}
