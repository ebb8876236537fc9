#version 460
// Level 0 of the camera-space depth pyramid: each pixel's reversed-Z depth turned into its
// distance along the camera's forward axis (0 where the pixel shows the sky); with `normals`,
// level 0 of the normals pyramid too (the G-buffer's octahedral normal, copied).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2, r32f) uniform writeonly image2D pyramid;
layout(set = 0, binding = 3) uniform sampler2D normal_tex;
layout(set = 0, binding = 4, rg16f) uniform writeonly image2D normal_pyramid;
layout(push_constant) uniform Push { ScreenAoConstants ao; };

#include "../common/screen_ao.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), frame.size.xy))) {
        return;
    }
    float depth = texelFetch(depth_tex, p, 0).r;
    float z = 0.0;
    if (depth > 0.0) {
        z = max(camera_depth(vec2(p) + 0.5, depth), 1e-6);
    }
    imageStore(pyramid, p, vec4(z));
    if (ao.normals != 0u) {
        imageStore(normal_pyramid, p, vec4(texelFetch(normal_tex, p, 0).rg, 0.0, 0.0));
    }
}
