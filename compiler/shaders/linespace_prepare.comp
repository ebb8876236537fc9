#version 460
// The line-space bake's per-triangle data on the GPU: one workgroup per cell, a thread per cell
// triangle. Each triangle's separating axes (geometry.rs: Prepared::new) and their separations
// from every face (Prepared::pair_axes) are written for the search; then it is clipped to the widened cell (geometry.rs: clip_to_box_into) and per face
// pair its key bounds (shafts.rs: key_bounds) and, for PNMT, its fallback records towards either
// end (shafts.rs: fallback_record) are written for the search and records kernels.
#extension GL_GOOGLE_include_directive : require
#define KILN_BAKE_TRI_BINDING 4
#include "linespace_common.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer ParamsB { BakeParams P; };
layout(std430, set = 0, binding = 1) readonly buffer CellsB { BakeCell cells[]; };
layout(std430, set = 0, binding = 2) readonly buffer CellTrisB { uint cell_tris[]; };
layout(std430, set = 0, binding = 3) readonly buffer LocalB { double local_corners[]; };
// Per cell triangle: the key minimum of each pair, then the key maximum.
layout(std430, set = 0, binding = 5) writeonly buffer KeysB { double keys[]; };
// Per cell triangle, pair and end: the fallback record.
layout(std430, set = 0, binding = 6) writeonly buffer FallbacksB { uint fallbacks[]; };
// Per cell triangle, face and separating axis: its separations from the face's patch (0, 0) on
// side 0 and side 1, and their steps per patch along u and v (Prepared::pair_axes).
layout(std430, set = 0, binding = 7) writeonly buffer FaceSepsB { double face_seps[]; };

// Axis `i` of the triangle with cell-relative corners v (Prepared::new's order: X, Y, Z, the
// normal, then X, Y, Z crossed with each edge).
dvec3 axis_of(uint i, dvec3 v0, dvec3 v1, dvec3 v2) {
    precise dvec3 e0 = v1 - v0;
    precise dvec3 e1 = v2 - v1;
    precise dvec3 e2 = v0 - v2;
    if (i < 3u) {
        dvec3 l = dvec3(0.0);
        l[i] = 1.0;
        return l;
    }
    if (i == 3u) {
        return dcross_glam(e0, e1);
    }
    uint b = (i - 4u) / 3u, k = (i - 4u) % 3u;
    dvec3 unit = dvec3(0.0);
    unit[b] = 1.0;
    return dcross_glam(unit, k == 0u ? e0 : (k == 1u ? e1 : e2));
}

// A triangle clipped to a box has at most 3 + 6 vertices.
const uint MAX_POLY = 9u;

// f64::total_cmp's order as a signed integer.
int64_t total_key(double x) {
    int64_t i = doubleBitsToInt64(x);
    return i ^ int64_t(uint64_t(i >> 63) >> 1);
}

// Barycentric weights of corners 1 and 2 at the point of the plane nearest p (shafts.rs:
// barycentric).
vec2 barycentric(uint t, vec3 p) {
    vec3 c0 = tri_vec(t, 0u), c1 = tri_vec(t, 1u), c2 = tri_vec(t, 2u);
    precise vec3 e1 = c1 - c0;
    precise vec3 e2 = c2 - c0;
    precise vec3 d = p - c0;
    precise float a = dot_glam(e1, e1);
    precise float b = dot_glam(e1, e2);
    precise float cc = dot_glam(e2, e2);
    precise float x = dot_glam(d, e1);
    precise float y = dot_glam(d, e2);
    precise float det = a * cc - b * b;
    if (det == 0.0) {
        return vec2(0.0);
    }
    precise float nu = cc * x - b * y;
    precise float nv = a * y - b * x;
    return vec2(fdiv(nu, det), fdiv(nv, det));
}

// The absent record (PnmtLayout::none).
uvec4 no_record(uint layout_code) {
    if (layout_code == BAKE_PNMT_FULL) {
        // PnmtRecord::NONE: material all ones, the rest zero.
        return uvec4(0u, BAKE_NO_RECORD << 16, 0u, 0u);
    }
    return uvec4((BAKE_NO_RECORD_COMPACT >> 10) << 30, (BAKE_NO_RECORD_COMPACT & 0x3ffu) << 22, 0u, 0u);
}

void main() {
    uint ci = gl_WorkGroupID.x;
    BakeCell c = cells[ci];
    dvec3 cmin = dvec3(c.gx, c.gy, c.gz);
    double lo = -P.margin;
    precise double hi = 1.0 + P.margin;
    for (uint li = gl_LocalInvocationID.x; li < c.tri_count; li += 64u) {
        uint ct = c.tri_first + li;
        uint t = cell_tris[ct];
        dvec3 poly[MAX_POLY];
        dvec3 tmp[MAX_POLY];
        uint count = 3u;
        for (uint k = 0u; k < 3u; ++k) {
            uint b = 9u * t + 3u * k;
            precise dvec3 v = dvec3(local_corners[b], local_corners[b + 1u], local_corners[b + 2u]) - cmin;
            poly[k] = v;
        }
        // The separating axes (Prepared::new) and their separations from each face's patches
        // (Prepared::pair_axes, per face).
        for (uint i = 0u; i < 13u; ++i) {
            dvec3 l = axis_of(i, poly[0], poly[1], poly[2]);
            precise double l1 = abs(l.x) + abs(l.y) + abs(l.z);
            precise double p0 = ddot_glam(l, poly[0]);
            precise double p1 = ddot_glam(l, poly[1]);
            precise double p2 = ddot_glam(l, poly[2]);
            double t0 = min(min(p0, p1), p2);
            double t1 = max(max(p0, p1), p2);
            for (uint face = 0u; face < 6u; ++face) {
                uint j = BAKE_FACE_AXIS[face], ua = BAKE_FACE_U[face], va = BAKE_FACE_V[face];
                double plane = double(face % 2u);
                precise double k = l[j] * plane + (l[ua] + l[va]) * P.half_s;
                precise double r = (abs(l[ua]) + abs(l[va])) * P.half_s + P.margin * l1;
                precise double s0 = k - r - t1;
                precise double s1 = t0 - k - r;
                precise double du = l[ua] * P.s;
                precise double dv = l[va] * P.s;
                uint b = ((ct * 6u + face) * 13u + i) * 4u;
                face_seps[b] = s0;
                face_seps[b + 1u] = s1;
                face_seps[b + 2u] = du;
                face_seps[b + 3u] = dv;
            }
        }
        // Sutherland–Hodgman against the widened cell, as clip_to_box_into.
        for (uint axis = 0u; axis < 3u; ++axis) {
            for (uint side = 0u; side < 2u; ++side) {
                if (count == 0u) {
                    break;
                }
                bool below = side == 1u;
                double bound = below ? hi : lo;
                uint out_count = 0u;
                for (uint i = 0u; i < count; ++i) {
                    dvec3 a = poly[i], b = poly[(i + 1u) % count];
                    bool ia = below ? a[axis] <= bound : a[axis] >= bound;
                    bool ib = below ? b[axis] <= bound : b[axis] >= bound;
                    if (ia && out_count < MAX_POLY) {
                        tmp[out_count++] = a;
                    }
                    if (ia != ib && out_count < MAX_POLY) {
                        precise double num = bound - a[axis];
                        precise double den = b[axis] - a[axis];
                        double s = num / den;
                        precise dvec3 ba = b - a;
                        precise dvec3 p = a + ba * s;
                        p[axis] = bound;
                        tmp[out_count++] = p;
                    }
                }
                count = out_count;
                for (uint i = 0u; i < count; ++i) {
                    poly[i] = tmp[i];
                }
            }
        }
        for (uint pair = 0u; pair < 15u; ++pair) {
            uint fa = BAKE_PAIR_A[pair], fb = BAKE_PAIR_B[pair];
            // outward(fb) − outward(fa).
            dvec3 oa = dvec3(0.0), ob = dvec3(0.0);
            oa[BAKE_FACE_AXIS[fa]] = fa % 2u == 0u ? -1.0 : 1.0;
            ob[BAKE_FACE_AXIS[fb]] = fb % 2u == 0u ? -1.0 : 1.0;
            precise dvec3 w = ob - oa;
            double kmin = 1.0 / 0.0, kmax = -1.0 / 0.0;
            uint first_min = 0u, first_max = 0u;
            int64_t best_min = 0, best_max = 0;
            for (uint i = 0u; i < count; ++i) {
                double k = ddot_glam(poly[i], w);
                kmin = min(kmin, k);
                kmax = max(kmax, k);
                // min_by with total_cmp: the first least (front) and first greatest (back).
                int64_t key = total_key(k);
                if (i == 0u || key < best_min) {
                    best_min = key;
                    first_min = i;
                }
                if (i == 0u || key > best_max) {
                    best_max = key;
                    first_max = i;
                }
            }
            if (count == 0u) {
                kmin = -1.0 / 0.0;
                kmax = 1.0 / 0.0;
            }
            keys[ct * 30u + pair] = kmin;
            keys[ct * 30u + 15u + pair] = kmax;
            if (P.records == 0u) {
                continue;
            }
            for (uint side = 0u; side < 2u; ++side) {
                uvec4 r;
                if (count == 0u) {
                    r = no_record(P.layout_code);
                } else {
                    dvec3 q = poly[side == 0u ? first_min : first_max];
                    dvec3 qc = min(max(q, dvec3(0.0)), dvec3(1.0));
                    precise dvec3 world = dvec3(c.wx, c.wy, c.wz) + qc * c.cell;
                    vec2 uv = barycentric(t, vec3(world));
                    uint material = uint(tri_data[20u * t + 18u]);
                    r = encode(world, shading_normal(t, uv.x, uv.y), material, c, P.layout_code);
                }
                uint f = ((ct * 15u + pair) * 2u + side) * P.words;
                for (uint k = 0u; k < P.words; ++k) {
                    fallbacks[f + k] = r[k];
                }
            }
        }
    }
}
