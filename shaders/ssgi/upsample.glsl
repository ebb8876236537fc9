// Joint bilateral upsampling (seed 000 §3.7, after Kopf et al. 2007) of the GI levels image: a
// texel of level `hi` from the 4 × 4 texels of level `lo` around it, each weighted by distance
// (Gaussian), by how well its surface matches the fine texel's (the fine point's distance to the
// coarse texel's plane, relative to its depth) and by normal agreement (the seed's threshold on
// the encoded normals' difference). Like the seed, the fine depth and normal are compared with the
// coarse ones the coarse value was gathered at. Where no coarse texel matches, plain bilinear.
// The includer declares `frame`, `pyramid` (r32f), `normal_pyramid` (rg16f) and `gi_levels`
// (rgba16f) and includes screen_ao.glsl.
#ifndef KILN_SSGI_UPSAMPLE_GLSL
#define KILN_SSGI_UPSAMPLE_GLSL

#include "../common/packing.glsl"

// The full-resolution image point of level `level`'s texel centre `t` (texel units).
vec2 level_to_image(vec2 t, int level) {
    return t * float(1 << level);
}

// The world point of level `level`'s texel `t` at camera depth z.
vec3 level_point(ivec2 t, int level, float z) {
    vec2 at = level_to_image(vec2(t) + 0.5, level);
    return pixel_origin(at) + pixel_ray(at) * z;
}

vec3 upsample(ivec2 q, int hi, int lo, float z, vec3 p, vec2 n_enc) {
    ivec2 size = pyramid_size(lo);
    ivec2 origin = pyramid_origin(lo);
    vec2 x = (vec2(q) + 0.5) / float(1 << (lo - hi)) - 0.5;
    ivec2 base = ivec2(floor(x)) - 1;
    vec2 f = x - vec2(base + 1);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    vec3 bilinear = vec3(0.0);
    for (int j = 0; j < 4; j++) {
        for (int i = 0; i < 4; i++) {
            ivec2 c = clamp(base + ivec2(i, j), ivec2(0), size - 1);
            vec3 value = imageLoad(gi_levels, origin + c).rgb;
            if (i >= 1 && i <= 2 && j >= 1 && j <= 2) {
                bilinear += value * (i == 1 ? 1.0 - f.x : f.x) * (j == 1 ? 1.0 - f.y : f.y);
            }
            float zc = imageLoad(pyramid, origin + c).r;
            if (zc <= 0.0) {
                continue;
            }
            vec2 nc_enc = imageLoad(normal_pyramid, origin + c).rg;
            vec3 nc = oct_decode(nc_enc);
            vec2 d = vec2(base + ivec2(i, j)) - x;
            float spatial = exp(-dot(d, d) / (2.0 * 1.5 * 1.5));
            float plane = dot(p - level_point(c, lo, zc), nc) / (0.02 * z);
            float depth_w = exp(-0.5 * plane * plane);
            vec2 dn = n_enc - nc_enc;
            float normal_w = max(0.005, 1.0 - smoothstep(0.05, 0.2, dot(dn, dn)));
            float w = spatial * depth_w * normal_w;
            sum += value * w;
            weight += w;
        }
    }
    return weight < 1e-3 ? bilinear : sum / weight;
}

#endif
