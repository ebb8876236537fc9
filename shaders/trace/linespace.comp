#version 460
// Traces a buffer of rays through the line space (shaders/common/linespace.glsl), one query per
// dispatch chosen by `mode`; used to check the GPU queries against the CPU's and to measure their
// throughput next to the BVH traversal (trace/rays.comp) on the same rays.
//   0: candidates, closest hit        1: candidates, any hit
//   2: binary, conservative any hit   3: PNMT approximate hit (origin normals from `normals`)
//   4: binary with exact end cells    5: binary with exact tests in filled shafts
layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer BvhNodes { uvec4 bvh_nodes[]; };
layout(set = 0, binding = 1, std430) readonly buffer BvhTriangles { vec4 bvh_tris[]; };
// Per ray: (origin, tmin), (direction, tmax).
layout(set = 0, binding = 2, std430) readonly buffer Rays { vec4 rays[]; };
// Per ray: closest/any hit (t or NO_HIT, triangle as float bits, u, v); PNMT (t or NO_HIT,
// material as float bits, uv).
layout(set = 0, binding = 3, std430) writeonly buffer Hits { vec4 hits[]; };
// Per ray: the geometric normal of the surface it leaves (PNMT's self-hit rule), or zero.
layout(set = 0, binding = 4, std430) readonly buffer Normals { vec4 normals[]; };
layout(push_constant) uniform Params { uint count; uint mode; };

#include "../common/traverse.glsl"
#define LS_BINDING 5
#include "../common/linespace.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) {
        return;
    }
    vec4 o = rays[2u * i];
    vec4 d = rays[2u * i + 1u];
    TraceRay r = make_ray(o.xyz, d.xyz, o.w, d.w);
    vec4 out_hit = vec4(NO_HIT, uintBitsToFloat(0xffffffffu), 0.0, 0.0);
    if (mode <= 1u) {
        TraceHit h = ls_trace_candidates(r, mode == 1u);
        out_hit = vec4(h.t, uintBitsToFloat(h.triangle), h.u, h.v);
    } else if (mode == 2u) {
        out_hit.x = ls_any_binary(o.xyz, d.xyz, o.w, d.w) ? 0.0 : NO_HIT;
    } else if (mode == 3u) {
        LsRecord rec;
        if (ls_pnmt_hit(o.xyz, d.xyz, o.w, d.w, normals[i].xyz, rec)) {
            out_hit = vec4(rec.t, uintBitsToFloat(rec.material), rec.uv);
        }
    } else {
        out_hit.x = ls_occluded_binary(r, mode == 5u) ? 0.0 : NO_HIT;
    }
    hits[i] = out_hit;
}
