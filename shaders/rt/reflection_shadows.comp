#version 460
// Shadow rays at the reflection hits (see reflections.comp), and at the hits of metal hits' own
// reflections: for each light with a stored unshadowed term, one hard shadow ray from the hit
// towards the light's centre (or along a directional light); visible terms are added to the partial radiance, and the sample is
// averaged into the reflection image over frames.
#include "hybrid.glsl"

// The stored terms of the first `count` lights (from layer `first` on) that a shadow ray from
// `origin` finds unoccluded, summed.
vec3 lit_terms(ivec2 c, vec3 origin, uint first, uint count) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < count; i++) {
        vec3 term = imageLoad(refl_lights, ivec3(c, int(first + i))).rgb;
        if (!any(greaterThan(term, vec3(0.0)))) {
            continue;
        }
        GpuLight l = lights[i];
        bool blocked = l.kind == LIGHT_DIRECTIONAL ? occluded_ray_from(origin, -l.direction) : occluded_from(origin, l.position);
        if (!blocked) {
            sum += term;
        }
    }
    return sum;
}

void main() {
    uvec2 cell = gl_GlobalInvocationID.xy;
    uvec2 cells = (frame.size.xy + rt.reflection_step - 1u) / rt.reflection_step;
    if (any(greaterThanEqual(cell, cells))) {
        return;
    }
    ivec2 c = ivec2(cell);
    vec4 value = imageLoad(refl_partial, c);
    vec4 origin = imageLoad(refl_origin, c);
    if (origin.w > 0.0) {
        value.rgb += lit_terms(c, origin.xyz, 0u, rt.reflection_lights);
        // A metal hit's own reflection's hit (reflections.comp, `traced_onwards`): the terms of
        // its first REFLECTION_SECOND_HIT_LIGHTS lights follow the first hit's, its origin after
        // them.
        uint count = min(rt.reflection_lights, REFLECTION_SECOND_HIT_LIGHTS);
        vec4 second = imageLoad(refl_lights, ivec3(c, int(rt.reflection_lights + count)));
        if (second.w > 0.0) {
            value.rgb += lit_terms(c, second.xyz, rt.reflection_lights, count);
        }
    }
    if (any(isnan(value)) || any(isinf(value))) {
        value = vec4(0.0, 0.0, 0.0, value.a > 0.0 ? 1.0 : 0.0);
    }
    imageStore(rt_reflections, c, accumulate(imageLoad(rt_reflections, c), value));
}
