// The peer of kiln's compute traversal: the driver's ray-tracing pipeline
// (VK_KHR_ray_tracing_pipeline) tracing the same ray buffers into the same hit layout as
// shaders/trace/rays.comp, for throughput comparisons. Everything is reached through buffer
// device addresses in push constants, so the pipeline needs no descriptor set.
#ifndef KILN_PEER_COMMON_GLSL
#define KILN_PEER_COMMON_GLSL

#extension GL_EXT_ray_tracing : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Rays { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer Hits { vec4 v[]; };

layout(push_constant) uniform Params {
    uint64_t tlas;
    uint64_t rays;    // per ray: (origin, tmin), (direction, tmax)
    uint64_t hits;    // per ray: (t or NO_HIT, triangle as float bits, u, v)
    uint count;
    uint any_hit;
} pc;

struct Payload {
    float t;
    uint triangle;
    vec2 uv;
};

const float NO_HIT = 3.402823e38;

#endif
