#version 460
// Scalable ambient obscurance, the seed's modification (seed 000 §2.3, eq. 2.20–2.22, with
// erratum 6: the sum runs over the N samples 0..N−1). Per AO pixel c (every `step`-th screen
// pixel): N samples on a spiral of τ turns, rotated by the pixel's φ,
//   α_i = (i + ½)/N,  θ_i = 2π α_i τ + φ,  s_i = c + r' α_i (cos θ_i, sin θ_i),
// r' the world radius r projected at c; each sample's depth from pyramid level
// m_i = ⌊log₂(r' α_i / q')⌋ (q' = 2⁴, at most PYRAMID_TOP), its normal from the G-buffer;
//   A = max(0, 1 − 5/(r⁶N) Σ max(r² − v·v, 0)³ max((v·n − β)/(v·v + ε), 0) σ)^k,
//   σ = S(0.01, 0.2, |n·n_i|)·0.6 + 0.4 + S(0.8, 1, |n·n_i|)·2,  v = s − c,
// with the seed's β = 0.04, k = 2, ε = 0.01 for r = 1.8: lengths are measured in units of
// r/1.8 (the formula is not scale-free), so any radius behaves as the seed's 1.8 m in Sponza.
// Writes (A, camera depth of c) for the depth-aware blur (shaders/ao/blur.comp).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D g_normal;
layout(set = 0, binding = 2, r32f) uniform readonly image2D pyramid;
layout(set = 0, binding = 3, rg32f) uniform writeonly image2D raw;
layout(push_constant) uniform Push { ScreenAoConstants ao; };

#include "../common/packing.glsl"
#include "../common/screen_ao.glsl"

const float PI = 3.14159265358979;
const float SEED_RADIUS = 1.8;
const float BETA = 0.04;
const float K = 2.0;
const float EPSILON = 0.01;
// log₂ q': below a screen radius of 16 pixels samples read level 0.
const float LOG2_Q = 4.0;
// The coarsest level a sample reads (McGuire et al. 2012 stop at 5).
const int SAO_TOP = 5;

// The seed's smoothstep S_ss(l, r, x) (eq. 2.22).
float smooth_step(float l, float r, float x) {
    float t = clamp((x - l) / (r - l), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// The seed's weight σ of a sample by how parallel its normal is to the centre's (0.4 to 3).
float sigma(float c) {
    return smooth_step(0.01, 0.2, c) * 0.6 + 0.4 + smooth_step(0.8, 1.0, c) * 2.0;
}

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    int step = int(ao.step);
    if (any(greaterThanEqual(q, (ivec2(frame.size.xy) + step - 1) / step))) {
        return;
    }
    ivec2 c = q * step;
    float zc = imageLoad(pyramid, c).r;
    if (zc <= 0.0) {
        imageStore(raw, q, vec4(1.0, 0.0, 0.0, 0.0));
        return;
    }
    float unit = SEED_RADIUS / ao.radius;
    vec3 centre = point_at_depth(c, zc);
    vec3 n = oct_decode(texelFetch(g_normal, c, 0).rg);
    float r_px = ao.radius * pixels_per_unit(zc);
    float phi = 2.0 * PI * pixel_rotation(q);
    float r2 = SEED_RADIUS * SEED_RADIUS;
    float sum = 0.0;
    for (uint i = 0u; i < ao.count; i++) {
        float alpha = (float(i) + 0.5) / float(ao.count);
        float theta = 2.0 * PI * alpha * ao.turns + phi;
        float h = r_px * alpha;
        ivec2 s = ivec2(floor(vec2(c) + 0.5 + h * vec2(cos(theta), sin(theta))));
        if (any(lessThan(s, ivec2(0))) || any(greaterThanEqual(s, ivec2(frame.size.xy)))) {
            continue;
        }
        int m = clamp(int(floor(log2(h) - LOG2_Q)), 0, SAO_TOP);
        float zs = imageLoad(pyramid, pyramid_origin(m) + (s >> m)).r;
        if (zs <= 0.0) {
            continue;
        }
        vec3 v = (point_at_depth(s, zs) - centre) * unit;
        float vv = dot(v, v);
        vec3 ni = oct_decode(texelFetch(g_normal, s, 0).rg);
        float f = max(r2 - vv, 0.0);
        sum += f * f * f * max((dot(v, n) - BETA) / (vv + EPSILON), 0.0) * sigma(abs(dot(n, ni)));
    }
    float r6 = r2 * r2 * r2;
    float a = pow(max(0.0, 1.0 - 5.0 / (r6 * float(ao.count)) * sum), K);
    imageStore(raw, q, vec4(a, zc, 0.0, 0.0));
}
