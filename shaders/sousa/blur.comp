#version 460
#extension GL_EXT_control_flow_attributes : require
// One of Sousa's first two blur passes (`--media sousa`, seed 002 §6, passes 2 and 3) for one
// light, at the depth map's resolution: the radial sum of the previous pass's image (sum.glsl),
// kept in 16-bit floats, not the seed's clamped 8 bits (its erratum 9).
#include "../common/layout.glsl"
#include "../common/lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, std430) readonly buffer Lights { GpuLight lights[]; };
layout(set = 0, binding = 2, std430) readonly buffer Media { GpuMedium media[]; };
layout(set = 0, binding = 3) uniform sampler2D previous;
layout(set = 0, binding = 4, r16f) uniform writeonly image2D blurred;
layout(push_constant) uniform Push { GodRayConstants gc; };

#include "../common/pixel.glsl"
#include "../common/media.glsl"
#include "../common/godrays.glsl"
#include "sum.glsl"

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(blurred);
    if (any(greaterThanEqual(texel, size))) {
        return;
    }
    vec2 light_uv;
    float sum = 0.0;
    if (light_on_screen(lights[gc.light], light_uv)) {
        sum = sousa_sum(previous, (vec2(texel) + 0.5) / vec2(size), light_uv);
    }
    imageStore(blurred, texel, vec4(sum));
}
