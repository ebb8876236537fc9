// Vertex attributes from the vertex buffers as the passes bind them: the includer declares
// `vertex_data` (6 floats per vertex: position, normal) and `vertex_attributes`
// (GpuVertexAttributes: texture coordinates, colour).
#ifndef KILN_VERTICES_GLSL
#define KILN_VERTICES_GLSL

vec3 vertex_position(uint v) {
    return vec3(vertex_data[6u * v], vertex_data[6u * v + 1u], vertex_data[6u * v + 2u]);
}

vec3 vertex_normal(uint v) {
    return vec3(vertex_data[6u * v + 3u], vertex_data[6u * v + 4u], vertex_data[6u * v + 5u]);
}

vec2 vertex_uv(uint v) {
    return vertex_attributes[v].uv;
}

// The vertex colour (COL0; white when the file has none), linear RGBA.
vec4 vertex_color(uint v) {
    uvec2 c = vertex_attributes[v].color;
    return vec4(unpackUnorm2x16(c.x), unpackUnorm2x16(c.y));
}

// The vertex colour at barycentrics (u, v) of the triangle with vertices `idx` (u weighs idx.y,
// v idx.z, as the intersection routines report them).
vec4 interpolated_color(uvec3 idx, float u, float v) {
    return (1.0 - u - v) * vertex_color(idx.x) + u * vertex_color(idx.y) + v * vertex_color(idx.z);
}

#endif
