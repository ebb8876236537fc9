#version 460
// The blur that completes Tóth's interleaved sampling (`--media toth`): each pixel averages the
// in-scattered radiance of the block × block tile around it, where every pixel took different
// samples of the march (an odd block: the block's own window; an even one: a window one wider,
// its border taps at half weight, so each of the block² sample sets still counts once), leaving
// out neighbours whose surface lies more than 10 % nearer or farther (no light across depth
// edges). Then the surface behind is dimmed by the media's transmittance along the pixel's own
// view ray and the average added.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, std430) readonly buffer Media { GpuMedium media[]; };
layout(set = 0, binding = 2) uniform sampler2D g_depth;
layout(set = 0, binding = 3) uniform sampler2D scatter;
layout(set = 0, binding = 4, rgba32f) uniform image2D radiance;
layout(push_constant) uniform Push { TothConstants tc; };

#include "../common/pixel.glsl"
#include "../common/media.glsl"

float distance_at(ivec2 pixel) {
    vec2 at = vec2(pixel) + 0.5;
    return surface_distance(at, texelFetch(g_depth, pixel, 0).r, pixel_origin(at), normalize(pixel_ray(at)));
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    float t = distance_at(pixel);
    int block = int(max(tc.block, 1u));
    int reach = block / 2;
    bool even = (block & 1) == 0;
    // The window, 2·reach + 1 wide, moved inside the image at its borders rather than cut: any
    // window that wide still holds every sample set once.
    ivec2 size = ivec2(frame.size.xy);
    ivec2 first = clamp(pixel - reach, ivec2(0), max(size - 1 - 2 * reach, ivec2(0)));
    ivec2 last = min(first + 2 * reach, size - 1);
    vec3 sum = vec3(0.0);
    float taken = 0.0;
    for (int y = first.y; y <= last.y; y++) {
        for (int x = first.x; x <= last.x; x++) {
            ivec2 q = ivec2(x, y);
            float w = (even && (x == first.x || x == first.x + 2 * reach) ? 0.5 : 1.0)
                    * (even && (y == first.y || y == first.y + 2 * reach) ? 0.5 : 1.0);
            if (q != pixel) {
                float tq = distance_at(q);
                bool sky = t == SKY_DISTANCE, sky_q = tq == SKY_DISTANCE;
                if (sky != sky_q || (!sky && abs(tq - t) > 0.1 * min(t, tq))) {
                    continue;
                }
            }
            vec4 s = texelFetch(scatter, q, 0);
            sum += w * s.rgb;
            taken += w * s.a;
        }
    }
    vec2 at = vec2(pixel) + 0.5;
    vec3 o = pixel_origin(at);
    vec3 d = normalize(pixel_ray(at));
    vec4 l0 = imageLoad(radiance, pixel);
    vec3 transmittance = exp(-optical_depth(tc.media, o, d, 0.0, t));
    // Σ w·sums / Σ w·counts is the mean over the samples taken, times the march's n: exact where
    // the window holds every sample set once (a count that is no multiple of block² included),
    // a ratio estimate where depth edges left neighbours out.
    vec3 scattered = taken > 0.0 ? sum * (float(max(tc.samples, 1u)) / taken) : vec3(0.0);
    imageStore(radiance, pixel, vec4(l0.rgb * transmittance + scattered, l0.a));
}
