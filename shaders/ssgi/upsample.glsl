// Joint bilateral upsampling (seed 000 §3.7, after Kopf et al. 2007) of the GI levels image: a
// texel of level `hi` from the texels of level `lo` around it, each weighted by distance, by how
// well its surface matches the fine texel's (the fine point's distance to the coarse texel's
// plane, relative to its depth) and by normal agreement (the seed's threshold on the encoded
// normals' difference). Like the seed, the fine point is compared with the coarse points the
// coarse values were gathered at. Between gathered levels: the 4 × 4 texels around, Gaussian
// distance weights (as the seed); to the screen: the 2 × 2 of a bilinear read, bilinear weights
// (a quarter of the reads, at the resolution where they cost most). Where no coarse texel
// matches, plain bilinear. The includer declares `frame`, `packed` (pack.comp) and `gi_levels`
// (rgba16f) and includes screen_ao.glsl.
#ifndef KILN_SSGI_UPSAMPLE_GLSL
#define KILN_SSGI_UPSAMPLE_GLSL

#include "../common/packing.glsl"
#include "packed.glsl"

// `p`: the fine point relative to the camera, `z` its camera depth, `n_enc` its encoded normal.
vec3 upsample(ivec2 q, int hi, int lo, float z, vec3 p, vec2 n_enc, bool wide) {
    ivec2 size = pyramid_size(lo);
    ivec2 origin = pyramid_origin(lo);
    vec2 x = (vec2(q) + 0.5) / float(1 << (lo - hi)) - 0.5;
    ivec2 corner = ivec2(floor(x));
    vec2 f = x - vec2(corner);
    int reach = wide ? 1 : 0;
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    vec3 bilinear = vec3(0.0);
    for (int j = -reach; j <= 1 + reach; j++) {
        for (int i = -reach; i <= 1 + reach; i++) {
            ivec2 c = clamp(corner + ivec2(i, j), ivec2(0), size - 1);
            vec3 value = imageLoad(gi_levels, origin + c).rgb;
            float b = 0.0;
            if (i >= 0 && i <= 1 && j >= 0 && j <= 1) {
                b = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
                bilinear += value * b;
            }
            uvec4 texel = imageLoad(packed, origin + c);
            vec3 pc = packed_point(texel);
            if (!packed_surface(pc)) {
                continue;
            }
            vec2 nc_enc = packed_normal(texel);
            float spatial = b + 1e-3;
            if (wide) {
                vec2 d = vec2(corner + ivec2(i, j)) - x;
                spatial = exp(-dot(d, d) / (2.0 * 1.5 * 1.5));
            }
            float plane = dot(p - pc, oct_decode(nc_enc)) / (0.02 * z);
            vec2 dn = n_enc - nc_enc;
            float w = spatial * exp(-0.5 * plane * plane) * max(0.005, 1.0 - smoothstep(0.05, 0.2, dot(dn, dn)));
            sum += value * w;
            weight += w;
        }
    }
    return weight < 1e-3 * (wide ? 1.0 : 0.01) ? bilinear : sum / weight;
}

#endif
