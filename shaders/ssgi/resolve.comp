#version 460
// Screen-space GI, last step: the finest gathered level brought to full resolution by joint
// bilateral upsampling (upsample.glsl), turned from irradiance into the mean incoming radiance
// (÷ π) that the direct pass multiplies by the diffuse weight, and averaged over the frames the
// camera has been still (capped at `cap` frames, after which it is an exponential average: the
// gathered light itself changes as the bounces build up frame by frame).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) uniform readonly image2D pyramid;
layout(set = 0, binding = 2, rg16f) uniform readonly image2D normal_pyramid;
layout(set = 0, binding = 3, rgba16f) uniform readonly image2D gi_levels;
layout(set = 0, binding = 4, rgba32f) uniform image2D gi_out;
layout(push_constant) uniform Push { ScreenGiConstants gi; };

#include "../common/screen_ao.glsl"
#include "upsample.glsl"

const float PI = 3.14159265358979;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), frame.size.xy))) {
        return;
    }
    float z = imageLoad(pyramid, p).r;
    vec3 mean_in = vec3(0.0);
    if (z > 0.0) {
        vec2 n_enc = imageLoad(normal_pyramid, p).rg;
        vec3 irradiance = gi.base == 0u
            ? imageLoad(gi_levels, p).rgb
            : upsample(p, 0, int(gi.base), z, level_point(p, 0, z), n_enc);
        mean_in = irradiance / PI;
    }
    if (gi.accumulated > 0u) {
        float w = 1.0 / float(min(gi.accumulated + 1u, max(gi.cap, 1u)));
        mean_in = mix(imageLoad(gi_out, p).rgb, mean_in, w);
    }
    imageStore(gi_out, p, vec4(mean_in, 1.0));
}
