#version 460
// Level `level` of the depth pyramid (and with `normals` of the normals pyramid) from the level
// below. Every texel copies one child of its 2 × 2 block unchanged, never an average, which
// would invent depths and normals between surfaces at every silhouette. Which child:
// - nearest: McGuire et al.'s rotated grid (2012, §2.2: child (1 − y mod 2, 1 − x mod 2)), so
//   that successive levels do not all keep the same corner;
// - voting (seed 000 §3.8, after Soler et al. 2010): the child whose depth and encoded normal
//   agree best with the means over the 4 × 4 children around the block, which prefers large
//   consistent regions and flickers less under motion. Seed 000's shader fetches the winner one
//   texel off (its erratum 7); here the scored child is the one copied. Its depth kernel is
//   σ = 0.001 of linear depth over the far plane; with camera distances and no far plane the
//   difference is taken relative to the mean (σ = 2 %).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) uniform image2D pyramid;
layout(set = 0, binding = 2, rg16f) uniform image2D normal_pyramid;
layout(push_constant) uniform Push { ScreenAoConstants ao; };

#include "../common/screen_ao.glsl"

const float SIGMA_NORMAL = 0.1;
const float SIGMA_DEPTH = 0.02;

float gauss(float x, float sigma) {
    return exp(-x * x / (2.0 * sigma * sigma));
}

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    int level = int(ao.level);
    if (any(greaterThanEqual(q, pyramid_size(level)))) {
        return;
    }
    ivec2 below = pyramid_size(level - 1);
    ivec2 origin = pyramid_origin(level - 1);
    ivec2 child = pyramid_child(q, below);
    if (ao.voting != 0u) {
        // Means over the 4 × 4 children around the block (sky texels left out).
        float z_sum = 0.0;
        vec2 n_sum = vec2(0.0);
        float count = 0.0;
        for (int j = -1; j <= 2; j++) {
            for (int i = -1; i <= 2; i++) {
                ivec2 c = clamp(2 * q + ivec2(i, j), ivec2(0), below - 1);
                float z = imageLoad(pyramid, origin + c).r;
                if (z > 0.0) {
                    z_sum += z;
                    n_sum += imageLoad(normal_pyramid, origin + c).rg;
                    count += 1.0;
                }
            }
        }
        if (count > 0.0) {
            float z_mean = z_sum / count;
            vec2 n_mean = n_sum / count;
            float best = -1.0;
            for (int k = 0; k < 4; k++) {
                ivec2 c = min(2 * q + ivec2(k & 1, k >> 1), below - 1);
                float z = imageLoad(pyramid, origin + c).r;
                if (z <= 0.0) {
                    continue;
                }
                vec2 n = imageLoad(normal_pyramid, origin + c).rg;
                float score = gauss((z - z_mean) / z_mean, SIGMA_DEPTH) * gauss(n.x - n_mean.x, SIGMA_NORMAL)
                    * gauss(n.y - n_mean.y, SIGMA_NORMAL);
                if (score > best) {
                    best = score;
                    child = c;
                }
            }
        }
    }
    imageStore(pyramid, pyramid_origin(level) + q, vec4(imageLoad(pyramid, origin + child).r));
    if (ao.normals != 0u) {
        imageStore(normal_pyramid, pyramid_origin(level) + q, imageLoad(normal_pyramid, origin + child));
    }
}
