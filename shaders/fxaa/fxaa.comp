#version 460
#extension GL_EXT_control_flow_attributes : require
// Fast approximate anti-aliasing (`--aa fxaa`; after Lottes, "FXAA", NVIDIA 2009, the 3.11
// quality variant): a one-frame post-process that finds edges in the composed radiance and
// blends each edge pixel with its neighbour across the edge by how far the pixel lies along the
// edge's staircase step, which is what the pixel's coverage would be for a straight edge.
//
// Per pixel:
// - perceptual luma (the exposed radiance's luminance L as sqrt(L / (1 + L)): edges are found
//   where the eye sees them, not where HDR values differ most) of the pixel and its 8
//   neighbours; below a local contrast of max(threshold_min, threshold × brightest) no edge;
// - the edge is horizontal or vertical by the larger of the two second differences, and lies
//   on the side of the steeper gradient;
// - from the edge's midpoint the search walks both ways along it (12 steps of growing length)
//   until the luma leaves the edge's average by a quarter of its gradient: the two ends;
// - the pixel nearer one end moves towards the neighbour across the edge by ½ − (distance to
//   that end) / (edge length), where the luma there says the step lies on its side;
// - single-pixel features get the sub-pixel blend instead when it is larger: the 3 × 3 mean's
//   difference from the pixel over the contrast, smoothstepped, squared, times `subpix`.
// The radiance itself is read bilinearly at the moved position (linear HDR values blended as the
// pixel's area would be). Only pixels on edges change; flat and smooth areas are left exactly.
#include "../common/layout.glsl"
#include "../common/packing.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D radiance;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D smoothed;
layout(push_constant) uniform Push { FxaaConstants fxaa; };

ivec2 size() {
    return ivec2(frame.size.xy);
}

vec3 texel(ivec2 p) {
    return imageLoad(radiance, clamp(p, ivec2(0), size() - 1)).rgb;
}

// The top-left texel of the 2 × 2 around `at` (pixel units, centres at k + ½) and the
// bilinear weights' fractions `f` towards the others.
ivec2 bilinear_base(vec2 at, out vec2 f) {
    vec2 x = at - 0.5;
    ivec2 b = ivec2(floor(x));
    f = x - vec2(b);
    return b;
}

// The radiance at `at`, bilinear.
vec3 bilinear(vec2 at) {
    vec2 f;
    ivec2 b = bilinear_base(at, f);
    return mix(mix(texel(b), texel(b + ivec2(1, 0)), f.x), mix(texel(b + ivec2(0, 1)), texel(b + ivec2(1, 1)), f.x), f.y);
}

float luma_of(vec3 c) {
    float l = max(luminance(c), 0.0) * frame.params.x;
    return sqrt(l / (1.0 + l));
}

float luma_at(ivec2 p) {
    return luma_of(texel(p));
}

// The lumas of the four texels around `at`, blended bilinearly (as FXAA's luma-in-alpha
// texture filters them): the luma of blended HDR colours would lie well above the mean of the
// two sides' lumas along a bright edge and end the search early.
float luma_bilinear(vec2 at) {
    vec2 f;
    ivec2 b = bilinear_base(at, f);
    return mix(mix(luma_at(b), luma_at(b + ivec2(1, 0)), f.x), mix(luma_at(b + ivec2(0, 1)), luma_at(b + ivec2(1, 1)), f.x), f.y);
}

const float STEPS[12] = float[12](1.0, 1.0, 1.0, 1.0, 1.0, 1.5, 2.0, 2.0, 2.0, 2.0, 4.0, 8.0);

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size()))) {
        return;
    }
    vec4 centre = imageLoad(radiance, p);
    float m = luma_of(centre.rgb);
    float n = luma_at(p + ivec2(0, -1));
    float s = luma_at(p + ivec2(0, 1));
    float e = luma_at(p + ivec2(1, 0));
    float w = luma_at(p + ivec2(-1, 0));
    float brightest = max(max(max(n, s), max(e, w)), m);
    float darkest = min(min(min(n, s), min(e, w)), m);
    float contrast = brightest - darkest;
    if (contrast < max(fxaa.threshold_min, brightest * fxaa.threshold)) {
        imageStore(smoothed, p, centre);
        return;
    }
    float nw = luma_at(p + ivec2(-1, -1));
    float ne = luma_at(p + ivec2(1, -1));
    float sw = luma_at(p + ivec2(-1, 1));
    float se = luma_at(p + ivec2(1, 1));

    // Sub-pixel: how far the pixel stands out of its 3 × 3 neighbourhood.
    float mean = (2.0 * (n + s + e + w) + (nw + ne + sw + se)) / 12.0;
    float sub = smoothstep(0.0, 1.0, clamp(abs(mean - m) / contrast, 0.0, 1.0));
    sub = sub * sub * fxaa.subpix;

    // Second differences across y of the three columns (a horizontal edge), across x of the
    // three rows (a vertical one).
    float across_y = abs(nw + sw - 2.0 * w) + 2.0 * abs(n + s - 2.0 * m) + abs(ne + se - 2.0 * e);
    float across_x = abs(nw + ne - 2.0 * n) + 2.0 * abs(w + e - 2.0 * m) + abs(sw + se - 2.0 * s);
    bool horizontal = across_y >= across_x;
    // The neighbours across the edge (negative side first) and the steeper side.
    float l_neg = horizontal ? n : w;
    float l_pos = horizontal ? s : e;
    float g_neg = abs(l_neg - m);
    float g_pos = abs(l_pos - m);
    bool negative = g_neg >= g_pos;
    float gradient = 0.25 * max(g_neg, g_pos);
    float side = negative ? l_neg : l_pos;
    float average = 0.5 * (side + m);
    vec2 normal = horizontal ? vec2(0.0, 1.0) : vec2(1.0, 0.0);
    vec2 along = horizontal ? vec2(1.0, 0.0) : vec2(0.0, 1.0);
    float sign_step = negative ? -1.0 : 1.0;

    // Walk from the edge's midpoint (half a pixel towards the steeper side) both ways.
    vec2 mid = vec2(p) + 0.5 + normal * (0.5 * sign_step);
    vec2 a = mid - along;
    vec2 b = mid + along;
    float end_a = luma_bilinear(a) - average;
    float end_b = luma_bilinear(b) - average;
    bool done_a = abs(end_a) >= gradient;
    bool done_b = abs(end_b) >= gradient;
    [[unroll]] for (int i = 1; i < 12; i++) {
        if (done_a && done_b) {
            break;
        }
        if (!done_a) {
            a -= along * STEPS[i];
            end_a = luma_bilinear(a) - average;
            done_a = abs(end_a) >= gradient;
        }
        if (!done_b) {
            b += along * STEPS[i];
            end_b = luma_bilinear(b) - average;
            done_b = abs(end_b) >= gradient;
        }
    }
    vec2 here = vec2(p) + 0.5;
    float dist_a = dot(here - a, along);
    float dist_b = dot(b - here, along);
    bool towards_a = dist_a < dist_b;
    float nearest = min(dist_a, dist_b);
    float length_ = dist_a + dist_b;
    float offset = 0.5 - nearest / length_;
    // The step lies on this pixel's side only where the luma at the nearer end moves away from
    // the edge's average the other way than the pixel does.
    bool centre_below = m < average;
    bool crossing = ((towards_a ? end_a : end_b) < 0.0) != centre_below;
    float shift = max(crossing ? offset : 0.0, sub);
    vec3 result = bilinear(here + normal * (shift * sign_step));
    imageStore(smoothed, p, vec4(result, centre.a));
}
