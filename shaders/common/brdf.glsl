// kiln's direct-light shading, mirroring compiler/src/shading.rs (the pre-illuminated line space
// bakes with the same functions). Units: radiance in W/(sr·m²).
#ifndef KILN_BRDF_GLSL
#define KILN_BRDF_GLSL

const float PI = 3.14159265358979;

struct Surface {
    vec3 base;        // linear base colour
    float metallic;
    float roughness;  // perceptual; alpha = roughness²
    bool diffuse_only;
};

// Directional albedo E = R + G of the split-sum table at (n·v, roughness), for multiple-scattering
// energy compensation; 1 when there is no table.
float directional_albedo(sampler2D lut, float lut_res, float n_v, float roughness) {
    if (lut_res < 1.0) {
        return 1.0;
    }
    vec2 rg = texture(lut, vec2(n_v, roughness)).rg;
    return max(rg.r + rg.g, 1e-3);
}

// f(l, v): Lambert for diffuse-only materials; otherwise Cook–Torrance GGX with height-correlated
// Smith visibility and Schlick Fresnel, F0 = mix(0.04, base, metallic), diffuse (1 − F)(1 − metallic)
// base / π, specular scaled by 1 + F0 (1 / E − 1).
vec3 brdf(Surface s, vec3 n, vec3 v, vec3 l, float e_albedo) {
    vec3 lambert = s.base / PI;
    if (s.diffuse_only) {
        return lambert;
    }
    vec3 h = normalize(v + l);
    float n_v = max(dot(n, v), 1e-4);
    float n_l = max(dot(n, l), 1e-4);
    float n_h = max(dot(n, h), 0.0);
    float v_h = max(dot(v, h), 0.0);
    float alpha = max(s.roughness * s.roughness, 1e-3);
    float a2 = alpha * alpha;
    float d_den = n_h * n_h * (a2 - 1.0) + 1.0;
    float d = a2 / (PI * d_den * d_den);
    float vis = 0.5 / (n_l * sqrt(n_v * n_v * (1.0 - a2) + a2) + n_v * sqrt(n_l * n_l * (1.0 - a2) + a2));
    vec3 f0 = mix(vec3(0.04), s.base, s.metallic);
    vec3 f = f0 + (vec3(1.0) - f0) * pow(1.0 - v_h, 5.0);
    vec3 compensation = vec3(1.0) + f0 * (1.0 / e_albedo - 1.0);
    return (vec3(1.0) - f) * (1.0 - s.metallic) * lambert + f * (d * vis) * compensation;
}

#endif
