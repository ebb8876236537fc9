#version 460
// Ray-traced ambient occlusion (seed 001 §1.4): one cosine-weighted ray per pixel around the
// shading normal, closest hit within `ao_radius`; a hit at distance t contributes (t / R)², a
// miss 1 (the thesis's distance weighting after Bavoil et al.), so the image holds openness,
// averaged over frames while the camera is still. A direction below the geometric surface (a
// normal-mapped normal tilts the hemisphere) counts as occluded at distance 0.
#include "hybrid.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    Primary s;
    float open = 1.0;
    if (primary_at(pixel, s)) {
        seed_rng(pixel, 2u);
        float r = sqrt(rnd());
        float phi = 2.0 * PI * rnd();
        vec3 dir = basis(s.n) * vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - r * r)));
        if (dot(dir, s.ng) <= 0.0) {
            open = 0.0;
        } else {
            TraceHit h = trace(make_ray(offset_ray_origin(s.p, s.ng), dir, 0.0, rt.ao_radius), false);
            open = h.t == NO_HIT ? 1.0 : (h.t / rt.ao_radius) * (h.t / rt.ao_radius);
        }
    }
    imageStore(rt_ao, pixel, vec4(accumulate(imageLoad(rt_ao, pixel).r, open)));
}
