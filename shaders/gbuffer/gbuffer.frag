#version 460
// G-buffer pass: material evaluation into four targets.
//   0 normal    RG16_SNORM  octahedral shading normal (normal map applied), world space
//   1 albedo    RGBA8_UNORM base colour, sRGB-encoded here (an SRGB format cannot be a storage
//                           image, and the visibility-buffer resolve writes the same targets)
//   2 material  RGBA8_UNORM metallic, roughness, diffuse-only flag, transmission or dielectric F0 (common/dielectric.glsl), occlusion
//   3 emission  RGBA16F     emitted radiance; alpha the clear coat (common/dielectric.glsl)
//   4 triangle  R32_UINT    1 + the triangle's index in the index buffer (0: nothing drawn); the
//                           ray-traced passes rebuild the exact surface point from it
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

layout(location = 0) out vec2 out_normal;
layout(location = 1) out vec4 out_albedo;
layout(location = 2) out vec4 out_material;
layout(location = 3) out vec4 out_emission;
layout(location = 4) out uint out_triangle;

void main() {
    vec4 base = material.base_color * in_color;
    if (material.base_color_texture != NO_TEXTURE) {
        base *= texture(base_color_tex, in_uv);
    }
    uint alpha_mode = (material.flags >> MATERIAL_ALPHA_SHIFT) & 3u;
    if (alpha_mode == 1u && base.a < material.alpha_cutoff) {
        discard;
    }
    bool double_sided = (material.flags & MATERIAL_DOUBLE_SIDED) != 0u;
    if (!double_sided && !gl_FrontFacing) {
        discard;
    }
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
}
