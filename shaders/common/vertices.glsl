// Vertex attributes from the vertex buffer as the passes bind it: the includer declares
// `vertex_data` (6 floats per vertex: position, normal).
#ifndef KILN_VERTICES_GLSL
#define KILN_VERTICES_GLSL

vec3 vertex_position(uint v) {
    return vec3(vertex_data[6u * v], vertex_data[6u * v + 1u], vertex_data[6u * v + 2u]);
}

vec3 vertex_normal(uint v) {
    return vec3(vertex_data[6u * v + 3u], vertex_data[6u * v + 4u], vertex_data[6u * v + 5u]);
}

#endif
