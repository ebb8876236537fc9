#version 460
// The denoiser, step 2 (svgf.glsl), for its one or two signals at once: each signal
// demodulated, and the standard deviation of its running mean.
layout(set = 0, binding = 1) uniform sampler2D g_albedo;
layout(set = 0, binding = 2, rg32ui) uniform readonly uimage2D guide;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D noisy[2];     // rgb mean, a: mean of luminance²
layout(set = 0, binding = 4, r32f) uniform readonly image2D samples;        // per pixel (reprojected)
layout(set = 0, binding = 5, rgba16f) uniform writeonly image2D filtered[2]; // rgb, a: the mean's standard deviation

#include "svgf.glsl"

// What signal i is divided by at pixel q.
vec3 demodulation(uint i, ivec2 q) {
    return signal_demodulator(i, texelFetch(g_albedo, q, 0).rgb);
}

vec4 load_noisy(uint i, ivec2 q) {
    return i == 0u ? imageLoad(noisy[0], q) : imageLoad(noisy[1], q);
}

void store(uint i, ivec2 pixel, vec4 v) {
    if (i == 0u) {
        imageStore(filtered[0], pixel, half_range(v));
    } else {
        imageStore(filtered[1], pixel, half_range(v));
    }
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    uint signals = min(push.signals, 2u);
    Guide g = unpack_guide(pixel, imageLoad(guide, pixel).xy);
    if (!g.surface) {
        for (uint i = 0u; i < signals; ++i) {
            store(i, pixel, vec4(load_noisy(i, pixel).rgb, 0.0));
        }
        return;
    }
    float n = push.samples > 0u ? float(push.samples) : max(imageLoad(samples, pixel).r, 1.0);
    if (n >= 4.0) {
        for (uint i = 0u; i < signals; ++i) {
            vec4 c = load_noisy(i, pixel);
            vec3 x = c.rgb / demodulation(i, pixel);
            float l = luminance(x);
            store(i, pixel, vec4(x, sqrt(max(c.a - l * l, 0.0) / n)));
        }
        return;
    }
    // Too few samples for the pixel's own moments: those of the 5 × 5 neighbours on the same
    // surface (weighted by geometry alone).
    float sw = 0.0, scale = push.sigma_plane * footprint(g.p);
    vec2 sl = vec2(0.0), sm = vec2(0.0);
    for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
            ivec2 q = pixel + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(uvec2(q), frame.size.xy))) {
                continue;
            }
            Guide gq = unpack_guide(q, imageLoad(guide, q).xy);
            if (!gq.surface) {
                continue;
            }
            float w = (dx == 0 && dy == 0) ? 1.0 : geometry_weight(g, gq, scale);
            sw += w;
            for (uint i = 0u; i < 2u; ++i) {
                if (i >= signals) {
                    break;
                }
                vec4 cq = load_noisy(i, q);
                sl[i] += w * luminance(cq.rgb / demodulation(i, q));
                sm[i] += w * cq.a;
            }
        }
    }
    for (uint i = 0u; i < 2u; ++i) {
        if (i < signals) {
            float mean = sl[i] / sw;
            float variance = max(sm[i] / sw - mean * mean, 0.0);
            store(i, pixel, vec4(load_noisy(i, pixel).rgb / demodulation(i, pixel), sqrt(variance / n)));
        }
    }
}
