#version 460
// The denoiser, step 2 (svgf.glsl), for one signal: the demodulated signal and the variance of
// its running mean.
layout(set = 0, binding = 1) uniform sampler2D g_albedo;
layout(set = 0, binding = 2, rgba32ui) uniform readonly uimage2D guide;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D noisy;     // rgb mean, a: mean of luminance²
layout(set = 0, binding = 4, r32f) uniform readonly image2D samples;     // per pixel (reprojected)
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D filtered; // rgb, a: variance of the mean

#include "svgf.glsl"

vec3 demodulation(ivec2 q) {
    return push.demodulate != 0u ? demodulator(srgb_to_linear(texelFetch(g_albedo, q, 0).rgb)) : vec3(1.0);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    vec4 c = imageLoad(noisy, pixel);
    Guide g = unpack_guide(imageLoad(guide, pixel));
    if (!g.surface) {
        imageStore(filtered, pixel, vec4(c.rgb, 0.0));
        return;
    }
    vec3 x = c.rgb / demodulation(pixel);
    float l = luminance(x);
    float n = push.samples > 0u ? float(push.samples) : max(imageLoad(samples, pixel).r, 1.0);
    float variance;
    if (n >= 4.0) {
        variance = max(c.a - l * l, 0.0);
    } else {
        // Too few samples for the pixel's own moments: those of the 5 × 5 neighbours on the
        // same surface (weighted by geometry alone).
        float sw = 0.0, sl = 0.0, sm = 0.0;
        for (int dy = -2; dy <= 2; ++dy) {
            for (int dx = -2; dx <= 2; ++dx) {
                ivec2 q = pixel + ivec2(dx, dy);
                if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(uvec2(q), frame.size.xy))) {
                    continue;
                }
                Guide gq = unpack_guide(imageLoad(guide, q));
                if (!gq.surface) {
                    continue;
                }
                float w = (dx == 0 && dy == 0) ? 1.0 : geometry_weight(g, gq, length(vec2(dx, dy)));
                vec4 cq = imageLoad(noisy, q);
                sw += w;
                sl += w * luminance(cq.rgb / demodulation(q));
                sm += w * cq.a;
            }
        }
        sl /= sw;
        variance = max(sm / sw - sl * sl, 0.0);
    }
    imageStore(filtered, pixel, vec4(x, variance / n));
}
