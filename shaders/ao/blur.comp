#version 460
// The screen-space AO passes' bilateral blur and upsampling (seed 000 §2.3: a Gaussian with
// depth weights): each screen pixel averages the raw AO pixels within BLUR_RADIUS of its
// position in the raw image (which is `step` times smaller), each weighted by a Gaussian of that
// distance times how close its camera depth is to the pixel's own (falling linearly to 0 at a
// relative difference of DEPTH_TOLERANCE): surfaces at other depths do not bleed in. The 7 × 7
// window holds every one of the 4 × 4 per-pixel rotations. Clamps the mean to [0, 1].
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) uniform readonly image2D pyramid;
layout(set = 0, binding = 2, rg32f) uniform readonly image2D raw;
layout(set = 0, binding = 3, r32f) uniform writeonly image2D ao_image;
layout(push_constant) uniform Push { ScreenAoConstants ao; };

#include "../common/screen_ao.glsl"

const int BLUR_RADIUS = 3;
const float SIGMA = 2.0;
const float DEPTH_TOLERANCE = 0.1;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), frame.size.xy))) {
        return;
    }
    float z = imageLoad(pyramid, p).r;
    if (z <= 0.0) {
        imageStore(ao_image, p, vec4(1.0));
        return;
    }
    int step = int(ao.step);
    ivec2 raw_size = (ivec2(frame.size.xy) + step - 1) / step;
    vec2 at = (vec2(p) + 0.5) / float(step) - 0.5;
    ivec2 base = ivec2(round(at));
    float sum = 0.0;
    float weights = 0.0;
    for (int dy = -BLUR_RADIUS; dy <= BLUR_RADIUS; dy++) {
        for (int dx = -BLUR_RADIUS; dx <= BLUR_RADIUS; dx++) {
            ivec2 t = base + ivec2(dx, dy);
            if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, raw_size))) {
                continue;
            }
            vec2 r = imageLoad(raw, t).rg;
            if (r.y <= 0.0) {
                continue;
            }
            vec2 o = vec2(t) - at;
            float w = exp(-dot(o, o) / (2.0 * SIGMA * SIGMA)) * max(0.0, 1.0 - abs(r.y - z) / (DEPTH_TOLERANCE * z));
            sum += w * r.x;
            weights += w;
        }
    }
    float a = weights > 0.0 ? sum / weights : imageLoad(raw, clamp(base, ivec2(0), raw_size - 1)).r;
    imageStore(ao_image, p, vec4(clamp(a, 0.0, 1.0)));
}
