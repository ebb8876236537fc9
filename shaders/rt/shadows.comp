#version 460
// Ray-traced soft shadows through the BVH (the estimator: shadows.glsl).
#include "hybrid.glsl"

bool shadow_occluded(vec3 from, vec3 ng, vec3 to) {
    return occluded(from, ng, to);
}

bool shadow_occluded_dir(vec3 from, vec3 ng, vec3 dir) {
    return occluded_ray(from, ng, dir);
}

#include "shadows.glsl"
