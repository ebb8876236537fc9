// The dielectric part's reflectance (glTF KHR_materials_ior and KHR_materials_specular): read
// from a material record, and carried through the raster G-buffer.
//
// In the record (FORMAT.md, "Materials"): with MATERIAL_SPECULAR, `specular` holds F0 (RGB) and
// F90 as four half floats; without it glTF's core values, F0 0.04 and F90 1.
//
// In the G-buffer, whose targets are 8-bit: the material target's blue channel is 1 for
// diffuse-only materials and otherwise k/255 with the grey F0 = (k/125)², k ≤ 125 (0.04 is
// exact at k = 25), or, for a surface that transmits (KHR_materials_transmission), k = 127 +
// round(127 t), 128..254, with glTF's core F0 (packing.glsl decodes it); the albedo target's
// alpha holds F90. The raster frame thus reflects with the F0's luminance, and a transmitting
// surface with the core's: coloured dielectric F0 (specularColorFactor) is kept by the
// ray-traced passes and the reference only.
#ifndef KILN_DIELECTRIC_GLSL
#define KILN_DIELECTRIC_GLSL

#include "layout.glsl"
#include "packing.glsl"
#include "brdf.glsl"

void material_dielectric(GpuMaterialLayout m, out vec3 f0, out float f90) {
    if ((m.flags & MATERIAL_SPECULAR) != 0u) {
        vec2 a = unpackHalf2x16(m.specular.x);
        vec2 b = unpackHalf2x16(m.specular.y);
        f0 = vec3(a, b.x);
        f90 = b.y;
    } else {
        f0 = DIELECTRIC_F0;
        f90 = 1.0;
    }
}

// What the G-buffer holds of material `m`'s reflectance where it transmits `transmission`: x the
// material target's blue channel (1 diffuse-only, the coded transmission, else the coded grey
// F0), y the albedo target's alpha (F90).
vec2 gbuffer_dielectric(GpuMaterialLayout m, float transmission) {
    vec3 f0;
    float f90;
    material_dielectric(m, f0, f90);
    bool diffuse_only = (m.flags & MATERIAL_DIFFUSE_ONLY) != 0u;
    float t = round(clamp(transmission, 0.0, 1.0) * GBUFFER_TRANSMISSION_STEPS);
    float code = diffuse_only ? 255.0
        : t > 0.0 ? GBUFFER_TRANSMISSION_STEPS + t : round(sqrt(clamp(luminance(f0), 0.0, 1.0)) * 125.0);
    return vec2(code / 255.0, f90);
}

// The material at a pixel from the G-buffer's albedo and material texels.
Material gbuffer_material(vec4 albedo, vec4 mat) {
    Material m;
    m.base = srgb_to_linear(albedo.rgb);
    m.metallic = mat.r;
    m.roughness = mat.g;
    m.diffuse_only = gbuffer_diffuse_only(mat);
    m.transmission = gbuffer_transmission(mat);
    float k = min(round(mat.b * 255.0), 125.0) / 125.0;
    m.f0 = m.transmission > 0.0 ? DIELECTRIC_F0 : vec3(k * k);
    m.f90 = albedo.a;
    // The clear coat is in the emission target's alpha (`gbuffer_coat`); the caller that reads
    // that target sets it.
    m.clearcoat = 0.0;
    m.clearcoat_roughness = 0.0;
    return m;
}

// The clear coat in the G-buffer: the emission target's alpha (half float, which holds whole
// numbers up to 2048 exactly) holds 32 · round(31 · clearcoat) + round(31 · roughness): 0 is no
// coat, and each parameter keeps steps of 1/31.
float gbuffer_coat(float clearcoat, float roughness) {
    return round(clamp(clearcoat, 0.0, 1.0) * 31.0) * 32.0 + round(clamp(roughness, 0.0, 1.0) * 31.0);
}

// The (clearcoat, roughness) that `gbuffer_coat` coded as `a`.
vec2 gbuffer_coat_decode(float a) {
    float k = round(clamp(a, 0.0, 1023.0));
    return vec2(floor(k / 32.0), mod(k, 32.0)) / 31.0;
}

#endif
