#version 460
// Diffuse global illumination (`gi.glsl`, the estimator) with its rays answered by the baked
// CWBVH: closest hits by `trace` and `surface_at`, shadow rays by `occluded` and `occluded_ray`.
// Every answer is exact, so `gi_hit` ignores `exact`.
#include "hybrid.glsl"

bool gi_hit(TraceRay r, vec3 origin_ng, bool exact, out Surface s) {
    return trace_surface(r, s);
}

bool gi_occluded(vec3 from, vec3 ng, vec3 to) {
    return occluded(from, ng, to);
}

bool gi_occluded_dir(vec3 from, vec3 ng, vec3 dir) {
    return occluded_ray(from, ng, dir);
}

#include "gi.glsl"

void main() {
    gi_main();
}
