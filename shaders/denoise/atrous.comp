#version 460
// The denoiser, step 3 (svgf.glsl), one à-trous iteration of one signal: src → dst, the last
// iteration remodulated into `result` (what the composition reads).
layout(set = 0, binding = 1) uniform sampler2D g_albedo;
layout(set = 0, binding = 2, rgba32ui) uniform readonly uimage2D guide;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D src;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D dst;
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D result;

#include "svgf.glsl"

// The B3-spline's weights at 0, 1 and 2 taps.
const float KERNEL[3] = float[3](0.375, 0.25, 0.0625);

void emit(ivec2 pixel, vec4 v) {
    if (push.last == 0u) {
        imageStore(dst, pixel, v);
        return;
    }
    vec3 d = push.demodulate != 0u ? demodulator(srgb_to_linear(texelFetch(g_albedo, pixel, 0).rgb)) : vec3(1.0);
    imageStore(result, pixel, vec4(v.rgb * d, 1.0));
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(frame.size.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec4 cp = imageLoad(src, pixel);
    Guide g = unpack_guide(imageLoad(guide, pixel));
    if (!g.surface) {
        emit(pixel, cp);
        return;
    }
    // The noise's standard deviation at p: the variance blurred over the 3 × 3 pixels around it
    // (a Gaussian), which steadies the estimate.
    float gv = 0.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = clamp(pixel + ivec2(dx, dy), ivec2(0), size - 1);
            gv += (dx == 0 ? 0.5 : 0.25) * (dy == 0 ? 0.5 : 0.25) * imageLoad(src, q).a;
        }
    }
    float lp = luminance(cp.rgb);
    // Relative floor: a converged pixel (variance 0) keeps its own value.
    float sigma = push.sigma_luminance * sqrt(gv) + 1e-6 * abs(lp) + 1e-30;
    int step = int(push.step);
    vec3 sum = vec3(0.0);
    float sum_w = 0.0, sum_v = 0.0;
    for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
            float h = KERNEL[abs(dx)] * KERNEL[abs(dy)];
            ivec2 q = pixel + ivec2(dx, dy) * step;
            vec4 cq = cp;
            float w = h;
            if (dx != 0 || dy != 0) {
                if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
                    continue;
                }
                Guide gq = unpack_guide(imageLoad(guide, q));
                if (!gq.surface) {
                    continue;
                }
                cq = imageLoad(src, q);
                float wl = exp(-abs(lp - luminance(cq.rgb)) / sigma);
                w *= geometry_weight(g, gq, length(vec2(dx, dy)) * float(step)) * wl;
            }
            sum += w * cq.rgb;
            sum_v += w * w * cq.a;
            sum_w += w;
        }
    }
    emit(pixel, vec4(sum / sum_w, sum_v / (sum_w * sum_w)));
}
