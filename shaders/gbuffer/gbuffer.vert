#version 460
// G-buffer pass: world-space vertices (the compiler flattened every instance), one draw per
// material.
#include "../common/layout.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_color;   // R16G16B16A16_UNORM: white without COL0

layout(location = 0) out vec3 out_position;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
// The draw's first triangle in the index buffer (drawn as its first instance).
layout(location = 3) flat out uint out_first_triangle;
layout(location = 4) out vec4 out_color;

void main() {
    out_position = in_position;
    out_normal = in_normal;
    out_uv = in_uv;
    out_color = in_color;
    out_first_triangle = uint(gl_InstanceIndex);
    gl_Position = frame.view_proj * vec4(in_position, 1.0);
}
