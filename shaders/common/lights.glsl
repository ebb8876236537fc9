// Analytic-light terms shared by the passes that shade with `GpuLight` (include layout.glsl
// first).
#ifndef KILN_LIGHTS_GLSL
#define KILN_LIGHTS_GLSL

// A spot light's cone falloff for the unit direction `l` from the shaded point towards the
// light: smoothstep from cos_outer to cos_inner, written out because GLSL leaves smoothstep
// undefined for equal edges.
float spot_cone(GpuLight light, vec3 l) {
    float t = clamp((dot(-l, light.direction) - light.cos_outer) / max(light.cos_inner - light.cos_outer, 1e-6), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

#endif
