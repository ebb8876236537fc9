// Generated from player/src/scene/bindings.rs by its test (KILN_BLESS=1 cargo test -p kiln-player
// scene_bindings): the scene as the passes that trace rays and shade their hits read it.
// Do not edit by hand.
#ifndef KILN_SCENE_BINDINGS_GLSL
#define KILN_SCENE_BINDINGS_GLSL

#include "layout.glsl"

// the baked CWBVH, 80-byte nodes as uvec4s
layout(set = 0, binding = 1, std430) readonly buffer BvhNodes { uvec4 bvh_nodes[]; };
// three corners per triangle in leaf order, xyz
layout(set = 0, binding = 2, std430) readonly buffer BvhTriangles { vec4 bvh_tris[]; };
// position and normal, 6 floats each
layout(set = 0, binding = 3, std430) readonly buffer Vertices { float vertex_data[]; };
// texture coordinates (zeros without) and colours (white without) per vertex
layout(set = 0, binding = 4, std430) readonly buffer VertexAttributes { GpuVertexAttributes vertex_attributes[]; };
// vertex indices in leaf order
layout(set = 0, binding = 5, std430) readonly buffer Indices { uint indices[]; };
// material of each triangle in leaf order
layout(set = 0, binding = 6, std430) readonly buffer TriMaterials { uint tri_materials[]; };
// the file's materials
layout(set = 0, binding = 7, std430) readonly buffer Materials { GpuMaterialLayout materials[]; };
// the analytic lights
layout(set = 0, binding = 8, std430) readonly buffer Lights { GpuLight lights[]; };

#endif
