#version 460
// Soft shadows by line-space shadow feelers (seed 004 §9): the estimator of shadows.glsl, its
// rays through the binary line space with exact triangle tests in every cell whose shaft is
// filled: the exact answer, the bits only skipping empty shafts.
#include "hybrid.glsl"
#define LS_BINDING 25
#include "../common/linespace.glsl"

bool shadow_feeler(vec3 o, vec3 dir, float tmax) {
    return ls_occluded_binary(make_ray(o, dir, 0.0, tmax), true);
}

// The segment's end pulled back as occluded_from does: the light's own surface never blocks.
bool shadow_occluded(vec3 from, vec3 ng, vec3 to) {
    vec3 o = offset_ray_origin(from, ng);
    vec3 d = to - o;
    float dist = length(d);
    return dist > 0.0 && shadow_feeler(o, d / dist, dist * (1.0 - 1e-5));
}

bool shadow_occluded_dir(vec3 from, vec3 ng, vec3 dir) {
    return shadow_feeler(offset_ray_origin(from, ng), dir, 3.4e38);
}

#include "shadows.glsl"
