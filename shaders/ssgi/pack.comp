#version 460
// Screen-space GI, first step: what a gather sample reads of the three pyramids (the point
// rebuilt from the camera depth, the encoded normal, the lit radiance) packed into one 16-byte
// texel (packed.glsl) per pyramid texel, so that each sample is one fetch and no unprojection.
// Covers the whole pyramid image for a full-resolution gather, the column of levels 1..
// otherwise.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) uniform readonly image2D pyramid;
layout(set = 0, binding = 2, rg16f) uniform readonly image2D normal_pyramid;
layout(set = 0, binding = 3, rgba16f) uniform readonly image2D lit;
layout(set = 0, binding = 4, rgba32ui) uniform writeonly uimage2D packed;
layout(push_constant) uniform Push { ScreenGiConstants gi; };

#include "../common/screen_ao.glsl"
#include "../common/packing.glsl"
#include "packed.glsl"

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (gi.base > 0u) {
        t.x += int(frame.size.x);
    }
    if (any(greaterThanEqual(t, imageSize(packed)))) {
        return;
    }
    // Which level the texel belongs to: level 0 left of the column, else by the column's rows.
    int level = 0;
    ivec2 local = t;
    if (t.x >= int(frame.size.x)) {
        level = 1;
        local = t - pyramid_origin(1);
        while (level < PYRAMID_TOP && local.y >= pyramid_size(level).y) {
            level++;
            local = t - pyramid_origin(level);
        }
        if (any(greaterThanEqual(local, pyramid_size(level)))) {
            return;
        }
    }
    float z = imageLoad(pyramid, t).r;
    vec4 light = imageLoad(lit, t);
    vec3 p = z > 0.0 ? level_point(local, level, z) - frame.camera.xyz : vec3(0.0);
    vec2 n_enc = imageLoad(normal_pyramid, t).rg;
    // The seed's cos α / cos β: α between the view ray and the camera's axis, β between the
    // view ray and the surface.
    vec3 view = camera_orthographic() ? frame.camera_forward.xyz : normalize(p);
    float cos_alpha = dot(view, frame.camera_forward.xyz);
    float cos_beta = abs(dot(view, oct_decode(n_enc)));
    float tilt = clamp(cos_alpha / max(cos_beta, 1e-6), 0.001, 1000.0);
    imageStore(packed, t, pack_texel(p, light.rgb * light.a, tilt, n_enc));
}
