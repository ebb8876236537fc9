#version 460
// Visibility-buffer resolve: the G-buffer targets of `gbuffer.frag`, written in compute from the
// triangle under each pixel. The surface point is the pixel-centre ray's barycentric point on
// that triangle; the rays through the next pixel in x and y, met with the same triangle's plane,
// give the uv and position differentials that hardware derivatives give the raster pass
// (texture level of detail and the normal map's cotangent frame). Textures are filtered
// trilinearly from the texel buffer's mip chains, like the raster pass's samplers.
#include "../common/layout.glsl"
#include "../common/packing.glsl"
#include "../common/normalmap.glsl"
#include "../common/dielectric.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, std430) readonly buffer Vertices { float vertex_data[]; };   // 6 floats each
layout(set = 0, binding = 2, std430) readonly buffer VertexAttributes { GpuVertexAttributes vertex_attributes[]; };
layout(set = 0, binding = 3, std430) readonly buffer RasterIndices { uint raster_indices[]; };
layout(set = 0, binding = 4, std430) readonly buffer RasterMaterials { uint raster_materials[]; };
layout(set = 0, binding = 5, std430) readonly buffer Materials { GpuMaterialLayout materials[]; };
layout(set = 0, binding = 6, std430) readonly buffer Texels { uint texels[]; };
layout(set = 0, binding = 7, std430) readonly buffer Textures { GpuTexture textures[]; };
// Written by the raster pass where something was drawn, undefined elsewhere (not cleared):
// pixels at the far plane are set to 0 here.
layout(set = 0, binding = 8, r32ui) uniform uimage2D g_triangle;
layout(set = 0, binding = 9, rg16_snorm) uniform writeonly image2D out_normal;
layout(set = 0, binding = 10, rgba8) uniform writeonly image2D out_albedo;
layout(set = 0, binding = 11, rgba8) uniform writeonly image2D out_material;
layout(set = 0, binding = 12, rgba16f) uniform writeonly image2D out_emission;
layout(set = 0, binding = 13) uniform sampler2D g_depth;

#include "../common/textures.glsl"
#include "../common/vertices.glsl"
#include "../common/pixel.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    // Reversed Z: nothing drawn leaves the cleared depth 0.
    bool drawn = texelFetch(g_depth, pixel, 0).r > 0.0;
    uint id = drawn ? imageLoad(g_triangle, pixel).r : 0u;
    if (id == 0u) {
        imageStore(g_triangle, pixel, uvec4(0u));
        // Nothing drawn: the direct pass shows the sky (depth 0) without reading these.
        imageStore(out_normal, pixel, vec4(0.0));
        imageStore(out_albedo, pixel, vec4(0.0));
        imageStore(out_material, pixel, vec4(0.0));
        imageStore(out_emission, pixel, vec4(0.0));
        return;
    }
    uint t = id - 1u;
    uvec3 idx = uvec3(raster_indices[3u * t], raster_indices[3u * t + 1u], raster_indices[3u * t + 2u]);
    vec3 p0 = vertex_position(idx.x), p1 = vertex_position(idx.y), p2 = vertex_position(idx.z);
    vec3 e1 = p1 - p0, e2 = p2 - p0;
    vec2 centre = vec2(pixel) + 0.5;
    vec3 dir = pixel_ray(centre);
    vec2 b = barycentrics(pixel_origin(centre), dir, p0, e1, e2);
    vec2 bx = barycentrics(pixel_origin(centre + vec2(1.0, 0.0)), pixel_ray(centre + vec2(1.0, 0.0)), p0, e1, e2);
    vec2 by = barycentrics(pixel_origin(centre + vec2(0.0, 1.0)), pixel_ray(centre + vec2(0.0, 1.0)), p0, e1, e2);
    GpuMaterialLayout m = materials[raster_materials[t]];
    vec2 t0 = vertex_uv(idx.x), t1 = vertex_uv(idx.y), t2 = vertex_uv(idx.z);
    vec2 uv = t0 + b.x * (t1 - t0) + b.y * (t2 - t0);
    vec2 duv_dx = (bx.x - b.x) * (t1 - t0) + (bx.y - b.y) * (t2 - t0);
    vec2 duv_dy = (by.x - b.x) * (t1 - t0) + (by.y - b.y) * (t2 - t0);

    vec3 n = (1.0 - b.x - b.y) * vertex_normal(idx.x) + b.x * vertex_normal(idx.y) + b.y * vertex_normal(idx.z);
    n = dot(n, n) > 0.0 ? normalize(n) : normalize(cross(e1, e2));
    // The rasteriser's front face is counter-clockwise on screen: the corners' normal faces the
    // camera. Back faces (drawn only for double-sided materials) flip the normal.
    bool front = dot(cross(e1, e2), dir) < 0.0;
    if (!front) {
        n = -n;
    }
    vec4 texel[MATERIAL_SLOTS];
    material_texels(m, ALL_MATERIAL_SLOTS, uv, duv_dx, duv_dy, texel);
    if (m.normal_texture != NO_TEXTURE) {
        vec3 dp_dx = (bx.x - b.x) * e1 + (bx.y - b.y) * e2;
        vec3 dp_dy = (by.x - b.x) * e1 + (by.y - b.y) * e2;
        vec3 ts = normal_texel(texel[SLOT_NORMAL]);
        n = normal_mapped(n, dp_dx, dp_dy, duv_dx, duv_dy, ts, m.normal_scale);
    }
    vec4 base = m.base_color * interpolated_color(idx, b.x, b.y) * texel[SLOT_BASE_COLOR];
    vec4 mr = texel[SLOT_METALLIC_ROUGHNESS];
    float metallic = m.metallic * mr.b;
    float roughness = m.roughness * mr.g;
    float occlusion = 1.0;
    if (m.occlusion_texture != NO_TEXTURE) {
        occlusion = mix(1.0, texel[SLOT_OCCLUSION].r, m.occlusion_strength);
    }
    vec3 emission = m.emission * texel[SLOT_EMISSIVE].rgb;
    imageStore(out_normal, pixel, vec4(oct_encode(n), 0.0, 0.0));
    float transmission = m.transmission * texel[SLOT_TRANSMISSION].r;
    vec2 dielectric = gbuffer_dielectric(m, transmission);
    imageStore(out_albedo, pixel, vec4(linear_to_srgb(base.rgb), dielectric.y));
    imageStore(out_material, pixel, vec4(clamp(metallic, 0.0, 1.0), clamp(roughness, 0.0, 1.0), dielectric.x, occlusion));
    float coat = gbuffer_coat(m.clearcoat * texel[SLOT_CLEARCOAT].r, m.clearcoat_roughness * texel[SLOT_CLEARCOAT_ROUGHNESS].g);
    imageStore(out_emission, pixel, vec4(emission, coat));
}
