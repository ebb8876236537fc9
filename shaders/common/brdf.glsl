// The glTF metallic-roughness BRDF, once for every pass: GGX normal distribution, height-correlated
// Smith masking-shadowing, Schlick Fresnel, Lambert diffuse. The direct-light evaluation `brdf`
// mirrors compiler/src/shading.rs (the pre-illuminated line space bakes with the same
// functions); the ray-traced passes build their estimators (common/scene.glsl,
// rt/reflections.comp) from the same pieces. Units: radiance in W/(sr·m²).
#ifndef KILN_BRDF_GLSL
#define KILN_BRDF_GLSL

const float PI = 3.14159265358979;

// A surface's material as the BRDF sees it.
struct Material {
    vec3 base;        // linear base colour
    float metallic;
    float roughness;  // perceptual; alpha = roughness²
    bool diffuse_only;
    vec3 f0;          // the dielectric part's Schlick reflectance at normal incidence (glTF core 0.04)
    float f90;        // … at grazing incidence (glTF core 1; KHR_materials_specular's factor)
    float clearcoat;  // KHR_materials_clearcoat's strength (0: no coat); passes that trace rays only
    float clearcoat_roughness;  // the coat's perceptual roughness
    float transmission;  // KHR_materials_transmission's thin-walled transmission (0: opaque)
};

// glTF's core dielectric reflectance (an index of refraction of 1.5), without
// KHR_materials_ior/specular.
const vec3 DIELECTRIC_F0 = vec3(0.04);

// GGX alpha of a perceptual roughness, kept away from 0 (a perfect mirror's delta lobe).
float ggx_alpha(float roughness) {
    return max(roughness * roughness, 1e-3);
}

// GGX normal distribution D(h) at n·h, for a2 = alpha².
float ggx_d(float n_h, float a2) {
    float d = n_h * n_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

// Smith Λ of GGX for a direction at cosine c to the normal.
float smith_lambda(float c, float a2) {
    float c2 = max(c * c, 1e-12);
    return 0.5 * (sqrt(1.0 + a2 * (1.0 - c2) / c2) - 1.0);
}

// Smith G1 of GGX for a direction at cosine n_x to the normal.
float smith_g1(float n_x, float a2) {
    return 2.0 * n_x / (n_x + sqrt(a2 + (1.0 - a2) * n_x * n_x));
}

// Visibility V = G2 / (4 (n·l)(n·v)) with the height-correlated Smith G2 of GGX.
float smith_visibility(float n_l, float n_v, float a2) {
    return 0.5 / (n_l * sqrt(n_v * n_v * (1.0 - a2) + a2) + n_v * sqrt(n_l * n_l * (1.0 - a2) + a2));
}

// Reflectance at normal incidence: the dielectric's F0 (4 % in glTF's core), the base colour for
// metals.
vec3 fresnel_f0(Material m) {
    return mix(m.f0, m.base, m.metallic);
}

// Reflectance at grazing incidence: the dielectric's F90 (1 in glTF's core), 1 for metals.
vec3 fresnel_f90(Material m) {
    return vec3(mix(m.f90, 1.0, m.metallic));
}

// Schlick's Fresnel at the cosine `c` between the view (or light) direction and the half vector.
vec3 fresnel_schlick(vec3 f0, vec3 f90, float c) {
    return f0 + (f90 - f0) * pow(1.0 - c, 5.0);
}

// Lambert: the diffuse BRDF of albedo `base`.
vec3 lambert(vec3 base) {
    return base / PI;
}

// Directional albedo E = R + G of the split-sum table at (n·v, roughness), for multiple-scattering
// energy compensation; 1 when there is no table.
float directional_albedo(sampler2D lut, float lut_res, float n_v, float roughness) {
    if (lut_res < 1.0) {
        return 1.0;
    }
    vec2 rg = texture(lut, vec2(n_v, roughness)).rg;
    return max(rg.r + rg.g, 1e-3);
}

// KHR_materials_clearcoat's weight w = clearcoat · Fc, Fc the Schlick Fresnel of an index of
// refraction of 1.5 (F0 0.04) at the cosine n_v of the view direction to the coat's normal.
float coat_weight(float clearcoat, float n_v) {
    return clearcoat * fresnel_schlick(DIELECTRIC_F0, vec3(1.0), n_v).x;
}

// The coat's lobe D · Vis of perceptual roughness `roughness` (its Fresnel is in the weight).
float coat_lobe(float roughness, float n_h, float n_v, float n_l) {
    float a = ggx_alpha(roughness);
    float a2 = a * a;
    return ggx_d(n_h, a2) * smith_visibility(n_l, n_v, a2);
}

// The clear coat over the base's f: (1 − w) f + w D_c Vis_c (the coat's normal is the surface's
// here).
vec3 coat_over(Material m, vec3 base, float n_v, float n_h, float n_l) {
    float w = coat_weight(m.clearcoat, n_v);
    return base * (1.0 - w) + w * coat_lobe(m.clearcoat_roughness, n_h, n_v, n_l);
}

// f(l, v): Lambert for diffuse-only materials; otherwise Cook–Torrance GGX with height-correlated
// Smith visibility and Schlick Fresnel, F0 = mix(m.f0, base, metallic) (m.f0 0.04 in glTF's core), F90
// = mix(m.f90, 1, metallic), diffuse (1 − F)(1 − metallic)
// base / π, specular scaled by 1 + F0 (1 / E − 1); under a clear coat, `coat_over` of that.
vec3 brdf(Material m, vec3 n, vec3 v, vec3 l, float e_albedo) {
    vec3 diffuse = lambert(m.base);
    vec3 h = normalize(v + l);
    float n_v = max(dot(n, v), 1e-4);
    float n_l = max(dot(n, l), 1e-4);
    float n_h = max(dot(n, h), 0.0);
    if (m.diffuse_only) {
        return m.clearcoat > 0.0 ? coat_over(m, diffuse, n_v, n_h, n_l) : diffuse;
    }
    float v_h = max(dot(v, h), 0.0);
    float alpha = ggx_alpha(m.roughness);
    float a2 = alpha * alpha;
    float d = ggx_d(n_h, a2);
    float vis = smith_visibility(n_l, n_v, a2);
    vec3 f0 = fresnel_f0(m);
    vec3 f = fresnel_schlick(f0, fresnel_f90(m), v_h);
    vec3 compensation = vec3(1.0) + f0 * (1.0 / e_albedo - 1.0);
    vec3 base = (vec3(1.0) - f) * (1.0 - m.metallic) * (1.0 - m.transmission) * diffuse + f * (d * vis) * compensation;
    return m.clearcoat > 0.0 ? coat_over(m, base, n_v, n_h, n_l) : base;
}

// The thin-walled transmitted lobe's f (KHR_materials_transmission; FORMAT.md, "Transmission")
// towards v for light whose direction, mirrored through the surface, is `mirrored` (n·mirrored =
// n_l, n·v = n_v, both > 0): the specular lobe about it, tinted by the base colour, its light the
// dielectric diffuse part's share t: (1 − F)(1 − metallic) t base D Vis, F at the half vector.
// The one formula of the frame (`transmitted_brdf`) and the path tracer (`base_brdf_cos`).
vec3 transmitted_lobe(Material m, vec3 n, vec3 v, vec3 mirrored, float n_l, float n_v) {
    vec3 h = normalize(v + mirrored);
    float alpha = ggx_alpha(m.roughness);
    float a2 = alpha * alpha;
    vec3 f = fresnel_schlick(fresnel_f0(m), fresnel_f90(m), max(dot(v, h), 0.0));
    return (vec3(1.0) - f) * (1.0 - m.metallic) * m.transmission * m.base
        * (ggx_d(max(dot(n, h), 0.0), a2) * smith_visibility(n_l, n_v, a2));
}

// f(l, v) for light arriving from behind a thin-walled transmitting surface (n·l < 0): the
// transmitted lobe about l mirrored through the surface; under a clear coat, times the 1 − w the
// coat lets through. Zero for materials that do not transmit.
vec3 transmitted_brdf(Material m, vec3 n, vec3 v, vec3 l) {
    if (m.transmission <= 0.0 || m.diffuse_only) {
        return vec3(0.0);
    }
    vec3 mirrored = l - 2.0 * dot(n, l) * n;
    float n_v = max(dot(n, v), 1e-4);
    vec3 through = transmitted_lobe(m, n, v, mirrored, max(dot(n, mirrored), 1e-4), n_v);
    return m.clearcoat > 0.0 ? through * (1.0 - coat_weight(m.clearcoat, n_v)) : through;
}

// The share of the light from straight behind a thin-walled transmitting surface that its
// transmitted lobe lets through towards the viewer: the lobe's directional albedo without its
// Fresnel reflectance, (1 − metallic) t base ((R + G) − (F0 R + F90 G)) from the split-sum
// table's `rg` at n·v = `n_v` and the roughness (the integral of `transmitted_lobe`'s
// (1 − F) D Vis cos over the lobe), times the 1 − w a clear coat lets through. Zero for
// materials that do not transmit.
vec3 transmitted_albedo(Material m, float n_v, vec2 rg) {
    if (m.transmission <= 0.0 || m.diffuse_only) {
        return vec3(0.0);
    }
    vec3 lobe = vec3(rg.r + rg.g) - (fresnel_f0(m) * rg.r + fresnel_f90(m) * rg.g);
    vec3 through = (1.0 - m.metallic) * m.transmission * m.base * max(lobe, vec3(0.0));
    return m.clearcoat > 0.0 ? through * (1.0 - coat_weight(m.clearcoat, n_v)) : through;
}

#endif
