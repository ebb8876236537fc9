#version 460
// The line-space bake's search on the GPU: a thread per (cell, shaft), through the cell's
// triangles in list order, its two ends kept in registers. For each triangle the thread takes
// the separations of its 13 axes from the two faces that linespace_prepare.comp made
// (geometry.rs: Prepared::new, Prepared::pair_axes), their values at its two patches
// (PairAxes::masks) and the exact decision
// of PairAxes::shafts_among, with the same arithmetic; a shaft the triangle meets is filled as
// shafts.rs's Fills::fill fills it: its bit, the nearest hits of its midpoint segment from either
// end, and the fallback triangles by key.
#extension GL_GOOGLE_include_directive : require
#define KILN_BAKE_TRI_BINDING 4
#include "linespace_common.glsl"

layout(local_size_x = 128) in;

layout(std430, set = 0, binding = 0) readonly buffer ParamsB { BakeParams P; };
layout(std430, set = 0, binding = 1) readonly buffer CellsB { BakeCell cells[]; };
layout(std430, set = 0, binding = 2) readonly buffer CellTrisB { uint cell_tris[]; };
// Per cell triangle: the key minimum of each pair (15), then the key maximum (15).
layout(std430, set = 0, binding = 3) readonly buffer KeysB { double keys[]; };
// Per cell triangle, face and separating axis: its separations from the face's patch (0, 0) on
// side 0 and side 1, and their steps per patch along u and v.
layout(std430, set = 0, binding = 5) readonly buffer FaceSepsB { double face_seps[]; };
// Per shaft: its front and back ends, 3 words each (see FALLBACK).
layout(std430, set = 0, binding = 6) writeonly buffer EndsB { uint ends[]; };
layout(std430, set = 0, binding = 7) writeonly buffer BitsB { uint bits[]; };
// Per (cell, workgroup): the (triangle, shaft) pairs the sign masks left to decide.
layout(std430, set = 0, binding = 8) writeonly buffer TestsB { uint tests[]; };

// The workgroup's 128 shafts: four whole bit words of the cell.
shared uint sh_bits[4];
shared uint sh_tests;

// World centre of patch `pt` of face `face` (shafts.rs: patch_centres).
vec3 patch_centre(uint face, uint pt, BakeCell c) {
    dvec3 p = dvec3(0.0);
    p[BAKE_FACE_AXIS[face]] = double(face % 2u);
    p[BAKE_FACE_U[face]] = centre_coord(P, pt / P.n);
    p[BAKE_FACE_V[face]] = centre_coord(P, pt % P.n);
    precise double x = c.wx + p.x * c.cell;
    precise double y = c.wy + p.y * c.cell;
    precise double z = c.wz + p.z * c.cell;
    return vec3(float(x), float(y), float(z));
}

// The separations of axis `i` of cell triangle `ct` from patch (u, v) of face `face`: side 0
// and side 1 (PairAxes::a_end, and the masks' b end).
dvec2 separations(uint ct, uint i, uint face, double u, double v) {
    uint b = ((ct * 6u + face) * 13u + i) * 4u;
    precise double t = u * face_seps[b + 2u] + v * face_seps[b + 3u];
    precise double a0 = face_seps[b] + t;
    precise double a1 = face_seps[b + 1u] - t;
    return dvec2(a0, a1);
}

// Separation `c` (side·13 + axis) at the a end (patch (ua, va) of face fa) and the b end.
dvec2 separation_pair(uint ct, uint c, uint fa, double ua, double va, uint fb, double ub, double vb) {
    uint i = c % 13u, side = c / 13u;
    return dvec2(separations(ct, i, fa, ua, va)[side], separations(ct, i, fb, ub, vb)[side]);
}

void main() {
    uint ci = gl_WorkGroupID.y, tid = gl_LocalInvocationID.x;
    uint s = gl_WorkGroupID.x * 128u + tid;
    if (tid < 4u) {
        sh_bits[tid] = 0u;
    }
    if (tid == 0u) {
        sh_tests = 0u;
    }
    barrier();
    BakeCell c = cells[ci];
    bool live = s < P.shafts;
    uint pair = live ? s / P.n4 : 0u, k = s % P.n4;
    uint pa = k / P.n2, pb = k % P.n2;
    uint fa = BAKE_PAIR_A[pair], fb = BAKE_PAIR_B[pair];
    double ua = double(pa / P.n), va = double(pa % P.n), ub = double(pb / P.n), vb = double(pb % P.n);
    vec3 o = patch_centre(fa, pa, c), e_end = patch_centre(fb, pb, c);
    precise vec3 d = e_end - o;
    bool filled = false;
    End front = End(0.0, NONE, 0.0, 0.0, 0.0, NONE);
    End back = front;
    uint tested = 0u;
    for (uint li = 0u; live && li < c.tri_count; ++li) {
        uint ct = c.tri_first + li;
        // A triangle clipped away entirely (key minimum −∞, see linespace_prepare.comp) meets
        // nothing: the CPU bake skips it (shafts.rs: patch_sets).
        if (keys[ct * 30u] == -1.0 / 0.0) {
            continue;
        }
        // The sign masks at both ends; a separation positive at both rejects the shaft.
        uint lower = 0u, upper = 0u;
        bool rejected = false;
        for (uint i = 0u; i < 13u; ++i) {
            dvec2 sa = separations(ct, i, fa, ua, va);
            dvec2 sb = separations(ct, i, fb, ub, vb);
            if ((sa.x > 0.0 && sb.x > 0.0) || (sa.y > 0.0 && sb.y > 0.0)) {
                rejected = true;
                break;
            }
            lower |= uint(sa.x > 0.0) << i | uint(sa.y > 0.0) << (13u + i);
            upper |= uint(sb.x > 0.0) << i | uint(sb.y > 0.0) << (13u + i);
        }
        if (rejected) {
            continue;
        }
        tested += 1u;
        if (lower != 0u && upper != 0u) {
            // Roots as fractions num/den (den > 0), as PairAxes::shafts_among compares them.
            double lo_n = 0.0, lo_d = 1.0, hi_n = 1.0, hi_d = 1.0;
            uint m = lower;
            while (m != 0u) {
                uint cc = findLSB(m);
                m &= m - 1u;
                dvec2 ab = separation_pair(ct, cc, fa, ua, va, fb, ub, vb);
                precise double den = ab.x - ab.y;
                precise double x = ab.x * lo_d;
                precise double y = lo_n * den;
                if (x > y) {
                    lo_n = ab.x;
                    lo_d = den;
                }
            }
            m = upper;
            while (m != 0u) {
                uint cc = findLSB(m);
                m &= m - 1u;
                dvec2 ab = separation_pair(ct, cc, fa, ua, va, fb, ub, vb);
                precise double num = -ab.x;
                precise double den = ab.y - ab.x;
                precise double x = num * hi_d;
                precise double y = hi_n * den;
                if (x < y) {
                    hi_n = num;
                    hi_d = den;
                }
            }
            precise double x = lo_n * hi_d;
            precise double y = hi_n * lo_d;
            if (!(x <= y)) {
                continue;
            }
        }
        filled = true;
        if (P.records == 0u) {
            continue;
        }
        uint t = cell_tris[ct];
        // The midpoint segment (SegmentTest::new, then hit_if), where its crossing is nearer
        // either end.
        vec3 c0 = tri_vec(t, 0u), c1 = tri_vec(t, 1u), c2 = tri_vec(t, 2u);
        precise vec3 e01 = c1 - c0;
        precise vec3 e02 = c2 - c0;
        vec3 nn = cross_glam(e01, e02);
        precise float n2 = dot_glam(nn, nn);
        precise float denom = dot_glam(nn, d);
        if (denom != 0.0 && n2 != 0.0) {
            precise vec3 co = c0 - o;
            precise float num = dot_glam(nn, co);
            float th = fdiv(num, denom);
            bool wanted = front.hit == NONE || th < front.t || back.hit == NONE || th > back.t;
            if (th >= 0.0 && th <= 1.0 && wanted) {
                precise vec3 e12 = c2 - c1;
                precise vec3 e20 = c0 - c2;
                precise vec3 p = o + d * th;
                precise vec3 p0 = p - c0;
                precise vec3 p1 = p - c1;
                precise vec3 p2 = p - c2;
                precise float w0 = dot_glam(cross_glam(nn, e01), p0);
                precise float w1 = dot_glam(cross_glam(nn, e12), p1);
                precise float w2 = dot_glam(cross_glam(nn, e20), p2);
                if (w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0) {
                    float hu = fdiv(w2, n2), hv = fdiv(w0, n2);
                    if (front.hit == NONE || th < front.t) {
                        front.t = th;
                        front.hit = t;
                        front.u = hu;
                        front.v = hv;
                    }
                    if (back.hit == NONE || th > back.t) {
                        back.t = th;
                        back.hit = t;
                        back.u = hu;
                        back.v = hv;
                    }
                }
            }
        }
        // Fallbacks by key: the earliest triangle on ties.
        double kmin = keys[ct * 30u + pair], kmax = keys[ct * 30u + 15u + pair];
        if (front.local_tri == NONE || !(kmin >= front.key)) {
            front.key = kmin;
            front.local_tri = li;
        }
        if (back.local_tri == NONE || !(kmax <= back.key)) {
            back.key = kmax;
            back.local_tri = li;
        }
    }
    if (filled) {
        atomicOr(sh_bits[tid / 32u], 1u << (tid % 32u));
        if (P.records != 0u) {
            uint e = (ci * P.shafts + s) * 6u;
            ends[e] = front.hit != NONE ? front.hit : FALLBACK | front.local_tri;
            ends[e + 1u] = floatBitsToUint(front.u);
            ends[e + 2u] = floatBitsToUint(front.v);
            ends[e + 3u] = back.hit != NONE ? back.hit : FALLBACK | back.local_tri;
            ends[e + 4u] = floatBitsToUint(back.u);
            ends[e + 5u] = floatBitsToUint(back.v);
        }
    }
    if (tested != 0u) {
        atomicAdd(sh_tests, tested);
    }
    barrier();
    uint wps = (P.shafts + 31u) / 32u, w = gl_WorkGroupID.x * 4u + tid;
    if (tid < 4u && w < wps) {
        bits[ci * wps + w] = sh_bits[tid];
    }
    if (tid == 0u) {
        tests[ci * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sh_tests;
    }
}
