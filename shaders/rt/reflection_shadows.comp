#version 460
// Shadow rays at the reflection hits (see reflections.comp), and at the hits of metal hits' own
// reflections: for each light with a stored unshadowed term, one hard shadow ray from the hit
// towards the light's centre (or along a directional light); visible terms are added to the
// partial radiance, and the sample is averaged into the reflection image over frames.
#include "hybrid.glsl"

void main() {
    uvec2 cell = gl_GlobalInvocationID.xy;
    uvec2 cells = (frame.size.xy + rt.reflection_step - 1u) / rt.reflection_step;
    if (any(greaterThanEqual(cell, cells))) {
        return;
    }
    ivec2 c = ivec2(cell);
    vec4 value = imageLoad(refl_partial, c);
    vec4 origin = imageLoad(refl_origin, c);
    // The hit's lights (layers 0 …), then, where the hit was metal traced onwards
    // (reflections.comp, `traced_onwards`), its second hit's first REFLECTION_SECOND_HIT_LIGHTS
    // lights, whose layers follow the first hit's and whose origin follows them. One loop, so
    // that the traversal is compiled once into this lean kernel.
    uint second_lights = min(rt.reflection_lights, REFLECTION_SECOND_HIT_LIGHTS);
    uint first = 0u;
    uint count = rt.reflection_lights;
    for (uint hit = 0u; hit < 2u && origin.w > 0.0; hit++) {
        for (uint i = 0u; i < count; i++) {
            vec3 term = imageLoad(refl_lights, ivec3(c, int(first + i))).rgb;
            if (!any(greaterThan(term, vec3(0.0)))) {
                continue;
            }
            GpuLight l = lights[i];
            bool blocked = l.kind == LIGHT_DIRECTIONAL ? occluded_ray_from(origin.xyz, -l.direction)
                                                       : occluded_from(origin.xyz, l.position);
            if (!blocked) {
                value.rgb += term;
            }
        }
        first = rt.reflection_lights;
        count = second_lights;
        origin = imageLoad(refl_lights, ivec3(c, int(rt.reflection_lights + second_lights)));
    }
    if (any(isnan(value)) || any(isinf(value))) {
        value = vec4(0.0, 0.0, 0.0, value.a > 0.0 ? 1.0 : 0.0);
    }
    imageStore(rt_reflections, c, accumulate(imageLoad(rt_reflections, c), value));
}
