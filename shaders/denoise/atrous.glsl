// The denoiser, step 3 (svgf.glsl), one à-trous iteration of its one or two signals at once
// (each tap's geometry weighed once for both): src → dst, the last iteration remodulated into
// `result` (what the composition reads).
layout(set = 0, binding = 1) uniform sampler2D g_albedo;
layout(set = 0, binding = 2, rg32ui) uniform readonly uimage2D guide;
layout(set = 0, binding = 3, rgba16f) uniform readonly image2D src[2];   // rgb, a: standard deviation
layout(set = 0, binding = 4, rgba16f) uniform writeonly image2D dst[2];
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D result[2];

#include "svgf.glsl"

#ifndef RADIUS
#define RADIUS 2
#endif
#if RADIUS == 2
// The B3-spline's weights at 0, 1 and 2 taps.
const float KERNEL[3] = float[3](0.375, 0.25, 0.0625);
#else
// The linear B-spline's weights at 0 and 1 tap.
const float KERNEL[2] = float[2](0.5, 0.25);
#endif

// Image arrays are indexed by constants only: signal i through a branch.
vec4 load_src(uint i, ivec2 q) {
    return i == 0u ? imageLoad(src[0], q) : imageLoad(src[1], q);
}

void emit(uint i, ivec2 pixel, vec4 v) {
    if (push.last == 0u) {
        if (i == 0u) {
            imageStore(dst[0], pixel, half_range(v));
        } else {
            imageStore(dst[1], pixel, half_range(v));
        }
        return;
    }
    vec3 d = signal_demodulator(i, texelFetch(g_albedo, pixel, 0).rgb);
    if (i == 0u) {
        imageStore(result[0], pixel, vec4(v.rgb * d, 1.0));
    } else {
        imageStore(result[1], pixel, vec4(v.rgb * d, 1.0));
    }
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(frame.size.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    uint signals = min(push.signals, 2u);
    Guide g = unpack_guide(pixel, imageLoad(guide, pixel).xy);
    if (!g.surface) {
        for (uint i = 0u; i < 2u; ++i) {
            if (i < signals) {
                emit(i, pixel, load_src(i, pixel));
            }
        }
        return;
    }
    // Per signal: the pixel's luminance and the noise's standard deviation there, from the
    // variance blurred over the 3 × 3 pixels around it (a Gaussian), which steadies the estimate.
    vec4 cp[2] = vec4[2](vec4(0.0), vec4(0.0));
    vec2 lp = vec2(0.0), gv = vec2(0.0);
    // Loops over the signals have a constant bound (unrolled: the arrays stay in registers).
    for (uint i = 0u; i < 2u; ++i) {
        if (i >= signals) {
            break;
        }
        cp[i] = load_src(i, pixel);
        lp[i] = luminance(cp[i].rgb);
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                float sd = load_src(i, clamp(pixel + ivec2(dx, dy), ivec2(0), size - 1)).a;
                gv[i] += (dx == 0 ? 0.5 : 0.25) * (dy == 0 ? 0.5 : 0.25) * sd * sd;
            }
        }
    }
    // Relative floor: a converged pixel (variance 0) keeps its own value.
    vec2 sigma = push.sigma_luminance * sqrt(gv) + 1e-6 * abs(lp) + 1e-30;
    int step = int(push.step);
    vec3 sum[2] = vec3[2](vec3(0.0), vec3(0.0));
    vec2 sum_w = vec2(0.0), sum_v = vec2(0.0);
    float scale = push.sigma_plane * footprint(g.p);
    for (int dy = -RADIUS; dy <= RADIUS; ++dy) {
        for (int dx = -RADIUS; dx <= RADIUS; ++dx) {
            float h = KERNEL[abs(dx)] * KERNEL[abs(dy)];
            ivec2 q = pixel + ivec2(dx, dy) * step;
            bool centre = dx == 0 && dy == 0;
            float wg = h;
            if (!centre) {
                if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
                    continue;
                }
                Guide gq = unpack_guide(q, imageLoad(guide, q).xy);
                if (!gq.surface) {
                    continue;
                }
                wg *= geometry_weight(g, gq, scale);
            }
            for (uint i = 0u; i < 2u; ++i) {
                if (i >= signals) {
                    break;
                }
                vec4 cq = centre ? cp[i] : load_src(i, q);
                float w = centre ? wg : wg * exp(-abs(lp[i] - luminance(cq.rgb)) / sigma[i]);
                sum[i] += w * cq.rgb;
                sum_v[i] += w * w * cq.a * cq.a;
                sum_w[i] += w;
            }
        }
    }
    for (uint i = 0u; i < 2u; ++i) {
        if (i < signals) {
            emit(i, pixel, vec4(sum[i] / sum_w[i], sqrt(sum_v[i]) / sum_w[i]));
        }
    }
}
