#version 460
// Traces a buffer of rays through the baked BVH: closest or any hit per ray. Used to check the
// GPU traversal against the CPU query and to measure traversal throughput (rays/s).
layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer BvhNodes { uvec4 bvh_nodes[]; };
layout(set = 0, binding = 1, std430) readonly buffer BvhTriangles { vec4 bvh_tris[]; };
// Per ray: (origin, tmin), (direction, tmax).
layout(set = 0, binding = 2, std430) readonly buffer Rays { vec4 rays[]; };
// Per ray: (t or NO_HIT, triangle as float bits, u, v).
layout(set = 0, binding = 3, std430) writeonly buffer Hits { vec4 hits[]; };
layout(push_constant) uniform Params { uint count; uint any_hit; };

#include "../common/traverse.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) {
        return;
    }
    vec4 o = rays[2u * i];
    vec4 d = rays[2u * i + 1u];
    TraceHit h = trace(make_ray(o.xyz, d.xyz, o.w, d.w), any_hit != 0u);
    hits[i] = vec4(h.t, uintBitsToFloat(h.triangle), h.u, h.v);
}
