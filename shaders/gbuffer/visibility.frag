#version 460
// Visibility-buffer pass: only the triangle under each pixel (1 + its index in the index
// buffer) and depth; `gbuffer/resolve.comp` then evaluates the materials in compute. On GPUs
// whose raster hardware is small next to their compute (datacenter parts shade pixels on a few
// SMs), one 32-bit target instead of five makes the raster pass several times cheaper.
#include "../common/layout.glsl"

layout(set = 1, binding = 0) uniform sampler2D base_color_tex;
layout(push_constant) uniform Material { GpuMaterialLayout material; };

layout(location = 2) in vec2 in_uv;
layout(location = 3) flat in uint in_first_triangle;
layout(location = 4) in vec4 in_color;

layout(location = 0) out uint out_triangle;

void main() {
    uint alpha_mode = (material.flags >> MATERIAL_ALPHA_SHIFT) & 3u;
    if (alpha_mode == 1u) {
        float a = material.base_color.a * in_color.a;
        if (material.base_color_texture != NO_TEXTURE) {
            a *= texture(base_color_tex, in_uv).a;
        }
        if (a < material.alpha_cutoff) {
            discard;
        }
    }
    if ((material.flags & MATERIAL_DOUBLE_SIDED) == 0u && !gl_FrontFacing) {
        discard;
    }
    out_triangle = in_first_triangle + uint(gl_PrimitiveID) + 1u;
}
