#version 460
// Visibility-buffer pass for opaque one-sided materials: back faces are culled by the pipeline
// and nothing is discarded, so the depth test can reject hidden fragments before shading.
layout(location = 3) flat in uint in_first_triangle;

layout(location = 0) out uint out_triangle;

void main() {
    out_triangle = in_first_triangle + uint(gl_PrimitiveID) + 1u;
}
