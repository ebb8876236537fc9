// The raster G-buffer's material evaluation, shared by `gbuffer.frag` (the opaque surfaces) and
// `see_through.frag` (SEE_THROUGH defined: the nearest see-through surface in front of them).
// Targets:
//   0 normal    RG16_SNORM  octahedral shading normal (normal map applied), world space
//   1 albedo    RGBA8_UNORM base colour, sRGB-encoded here (an SRGB format cannot be a storage
//                           image, and the visibility-buffer resolve writes the same targets)
//   2 material  RGBA8_UNORM metallic, roughness, diffuse-only flag, transmission or dielectric F0 (common/dielectric.glsl), occlusion
//   3 emission  RGBA16F     emitted radiance; alpha the clear coat (common/dielectric.glsl)
//   4 triangle  R32_UINT    1 + the triangle's index in the index buffer (0: nothing drawn); the
//                           ray-traced passes rebuild the exact surface point from it
//   5 coverage  R8_UNORM    SEE_THROUGH only: the surface's alpha where it blends (glTF BLEND),
//                           else 1
// and, SEE_THROUGH_ABSORBED defined too, the one target of a pass of its own (blending it
// needs no per-target blend state):
//   0 absorbed  RGBA16F     summed over every see-through surface in front of the opaque one:
//                           −ln of the share of the light from straight behind that the surface
//                           lets through towards the camera, a T + (1 − a) for coverage a and
//                           T its `transmitted_albedo` (common/brdf.glsl; 0 where it does not
//                           transmit)
#include "../common/layout.glsl"
#include "../common/packing.glsl"
#include "../common/normalmap.glsl"
#include "../common/dielectric.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 1, binding = 0) uniform sampler2D base_color_tex;
layout(set = 1, binding = 1) uniform sampler2D metallic_roughness_tex;
layout(set = 1, binding = 2) uniform sampler2D normal_tex;
layout(set = 1, binding = 3) uniform sampler2D occlusion_tex;
layout(set = 1, binding = 4) uniform sampler2D emissive_tex;
layout(set = 1, binding = 5) uniform sampler2D clearcoat_tex;
layout(set = 1, binding = 6) uniform sampler2D clearcoat_roughness_tex;
layout(set = 1, binding = 7) uniform sampler2D transmission_tex;
layout(push_constant) uniform MaterialPush { GpuMaterialLayout material; };

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) flat in uint in_first_triangle;
layout(location = 4) in vec4 in_color;

#ifndef SEE_THROUGH_ABSORBED
layout(location = 0) out vec2 out_normal;
layout(location = 1) out vec4 out_albedo;
layout(location = 2) out vec4 out_material;
layout(location = 3) out vec4 out_emission;
layout(location = 4) out uint out_triangle;
#else
// The absorbed pass writes its one target alone (plain variables: the compiler drops the rest).
vec2 out_normal;
vec4 out_albedo;
vec4 out_material;
vec4 out_emission;
uint out_triangle;
#endif
#ifdef SEE_THROUGH
// The opaque surfaces' depth (reversed Z): a see-through fragment counts only in front of it.
layout(set = 0, binding = 1) uniform sampler2D opaque_depth;
layout(set = 0, binding = 2) uniform sampler2D brdf_lut;
#ifdef SEE_THROUGH_ABSORBED
layout(location = 0) out vec4 out_absorbed;
float out_coverage;
#else
layout(location = 5) out float out_coverage;
vec4 out_absorbed;
#endif
#include "../common/pixel.glsl"
#endif

void main() {
#ifdef SEE_THROUGH
    // The depth attachment keeps the nearest see-through fragment; this test keeps it in front
    // of the opaque surface (equal depth: the same surface or one coplanar, drawn opaque).
    if (gl_FragCoord.z <= texelFetch(opaque_depth, ivec2(gl_FragCoord.xy), 0).r) {
        discard;
    }
#endif
    vec4 base = material.base_color * in_color;
    if (material.base_color_texture != NO_TEXTURE) {
        base *= texture(base_color_tex, in_uv);
    }
    uint alpha_mode = (material.flags >> MATERIAL_ALPHA_SHIFT) & 3u;
    if (alpha_mode == 1u && base.a < material.alpha_cutoff) {
        discard;
    }
#ifdef SEE_THROUGH
    // A blended surface is there with probability alpha (the path tracer's reading); where alpha
    // is 0 nothing is there, and a see-through surface behind it may count instead.
    float coverage = alpha_mode == 2u ? clamp(base.a, 0.0, 1.0) : 1.0;
    if (coverage <= 0.0) {
        discard;
    }
    out_coverage = coverage;
#endif
    bool double_sided = (material.flags & MATERIAL_DOUBLE_SIDED) != 0u;
#ifndef SEE_THROUGH
    if (!double_sided && !gl_FrontFacing) {
        discard;
    }
#endif
    // A see-through surface keeps its back faces, one-sided or not: light passes a glass
    // shell's inner face from behind as the path tracer's rays do (every surface is two-sided
    // for them), and where no front face is nearer they are what the camera sees.
    vec3 n = normalize(in_normal);
    if (!gl_FrontFacing) {
        n = -n;
    }
    if (material.normal_texture != NO_TEXTURE) {
        n = normal_mapped(n, dFdx(in_position), dFdy(in_position), dFdx(in_uv), dFdy(in_uv),
            normal_texel(texture(normal_tex, in_uv)), material.normal_scale);
    }
    float metallic = material.metallic;
    float roughness = material.roughness;
    if (material.metallic_roughness_texture != NO_TEXTURE) {
        vec4 mr = texture(metallic_roughness_tex, in_uv);
        metallic *= mr.b;
        roughness *= mr.g;
    }
    float occlusion = 1.0;
    if (material.occlusion_texture != NO_TEXTURE) {
        occlusion = mix(1.0, texture(occlusion_tex, in_uv).r, material.occlusion_strength);
    }
    vec3 emission = material.emission;
    if (material.emissive_texture != NO_TEXTURE) {
        emission *= texture(emissive_tex, in_uv).rgb;
    }
    out_normal = oct_encode(n);
    float transmission = material.transmission;
    if (transmission > 0.0 && material.transmission_texture != NO_TEXTURE) {
        transmission *= texture(transmission_tex, in_uv).r;
    }
    vec2 dielectric = gbuffer_dielectric(material, transmission);
    out_albedo = vec4(linear_to_srgb(base.rgb), dielectric.y);
    out_material = vec4(clamp(metallic, 0.0, 1.0), clamp(roughness, 0.0, 1.0), dielectric.x, occlusion);
    float coat = material.clearcoat;
    float coat_roughness = material.clearcoat_roughness;
    if (coat > 0.0 && material.clearcoat_texture != NO_TEXTURE) {
        coat *= texture(clearcoat_tex, in_uv).r;
    }
    if (coat > 0.0 && material.clearcoat_roughness_texture != NO_TEXTURE) {
        coat_roughness *= texture(clearcoat_roughness_tex, in_uv).g;
    }
    out_emission = vec4(emission, gbuffer_coat(coat, coat_roughness));
    out_triangle = in_first_triangle + uint(gl_PrimitiveID) + 1u;
#ifdef SEE_THROUGH
    Material lit;
    lit.base = base.rgb;
    lit.metallic = clamp(metallic, 0.0, 1.0);
    lit.roughness = clamp(roughness, 0.0, 1.0);
    lit.diffuse_only = (material.flags & MATERIAL_DIFFUSE_ONLY) != 0u;
    material_dielectric(material, lit.f0, lit.f90);
    lit.clearcoat = clamp(coat, 0.0, 1.0);
    lit.clearcoat_roughness = clamp(coat_roughness, 0.0, 1.0);
    lit.transmission = clamp(transmission, 0.0, 1.0);
    float n_v = clamp(abs(dot(n, towards_camera(in_position))), 1e-4, 1.0);
    vec2 rg = frame.params.y >= 1.0 ? texture(brdf_lut, vec2(n_v, lit.roughness)).rg : vec2(1.0, 0.0);
    vec3 through = transmitted_albedo(lit, n_v, rg);
    vec3 passed = coverage * through + (1.0 - coverage);
    out_absorbed = vec4(-log(max(passed, vec3(1e-6))), 0.0);
#endif
}
