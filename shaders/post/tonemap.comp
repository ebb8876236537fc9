#version 460
// Exposure and tone mapping: display = sRGB(ACES(exposure · radiance)), where ACES is Narkowicz's
// fit of the ACES filmic reference curve, f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14),
// applied per channel and clamped to [0, 1].
#include "../common/layout.glsl"
#include "../common/packing.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D radiance_in;
layout(set = 0, binding = 2, rgba8) uniform writeonly image2D display_out;

vec3 aces(vec3 x) {
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    vec3 radiance = imageLoad(radiance_in, pixel).rgb;
    imageStore(display_out, pixel, vec4(linear_to_srgb(aces(radiance * frame.params.x)), 1.0));
}
