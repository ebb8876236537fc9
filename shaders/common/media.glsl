// Homogeneous participating media in axis-aligned boxes (`GpuMedium`): the ray's part inside a
// box, optical depth and transmittance over every box, the Henyey–Greenstein phase function.
// The includer declares the storage buffer `media` (GpuMedium) before including this file.
#ifndef KILN_MEDIA_GLSL
#define KILN_MEDIA_GLSL

// The part [t0, t1] of the unit ray (o, d) inside the box [lo, hi] (empty when x >= y). An axis
// the ray runs parallel to keeps all or nothing, without the NaN of 0 · ∞.
vec2 box_span(vec3 lo, vec3 hi, vec3 o, vec3 d, float t0, float t1) {
    for (int a = 0; a < 3; a++) {
        if (abs(d[a]) < 1e-30) {
            if (o[a] < lo[a] || o[a] > hi[a]) {
                return vec2(1.0, 0.0);
            }
        } else {
            float inv = 1.0 / d[a];
            float ta = (lo[a] - o[a]) * inv, tb = (hi[a] - o[a]) * inv;
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        }
    }
    return vec2(t0, t1);
}

vec3 medium_sigma_t(uint i) {
    return media[i].sigma_a.rgb + media[i].sigma_s.rgb;
}

// Optical depth (RGB) of the unit ray (o, d) over [t0, t1] through the first `count` media
// (overlapping boxes add).
vec3 optical_depth(uint count, vec3 o, vec3 d, float t0, float t1) {
    vec3 tau = vec3(0.0);
    for (uint i = 0u; i < count; i++) {
        vec2 span = box_span(media[i].min.xyz, media[i].max.xyz, o, d, t0, t1);
        if (span.y > span.x) {
            tau += medium_sigma_t(i) * (span.y - span.x);
        }
    }
    return tau;
}

// Henyey–Greenstein for light travelling along a unit direction and leaving along another at
// cos θ between them: (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}).
float hg(float g, float cos_theta) {
    float denom = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * 3.14159265358979 * denom * sqrt(max(denom, 1e-30)));
}

#endif
