#version 460
// The line-space bake's search on the GPU: one workgroup per (cell, face pair), the cell's
// triangles in list order. For each triangle the workgroup computes its 13 separating axes
// (geometry.rs: Prepared::new), their separations from every patch of the pair's two faces
// (PairAxes::pair_axes, PairAxes::masks) and, per shaft, the exact decision of
// PairAxes::shafts_among with the same arithmetic; then each shaft the triangle meets is filled as
// shafts.rs's Fills::fill fills it: its bit, the nearest hits of its midpoint segment from
// either end, and the fallback triangles by key.
#extension GL_GOOGLE_include_directive : require
#define KILN_BAKE_TRI_BINDING 5
#include "linespace_common.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer ParamsB { BakeParams P; };
layout(std430, set = 0, binding = 1) readonly buffer CellsB { BakeCell cells[]; };
layout(std430, set = 0, binding = 2) readonly buffer CellTrisB { uint cell_tris[]; };
// Per cell triangle: key minimum of each pair (15), then key maximum (15).
layout(std430, set = 0, binding = 3) readonly buffer KeysB { double keys[]; };
// Per global triangle: grid-local corners (9 doubles).
layout(std430, set = 0, binding = 4) readonly buffer LocalB { double local_corners[]; };
// Per global triangle: world corners (9 floats), vertex normals (9), material, padding.
layout(std430, set = 0, binding = 6) buffer EndsB { End ends[]; };
layout(std430, set = 0, binding = 7) buffer BitsB { uint bits[]; };
layout(std430, set = 0, binding = 8) buffer TestsB { uint tests[]; };

// Per axis: separations of face a (side 0, side 1, per u, per v), then of face b.
shared double sh_ax[13][8];
// Per patch of face a / b: the 26 separations (side·13 + axis), and which are positive.
shared double sh_sa[64][26];
shared double sh_sb[64][26];
shared uint sh_at_a[64];
shared uint sh_at_b[64];
// The pair's shaft bits (pair-local shaft pa·n² + pb).
shared uint sh_bits[128];
// World patch centres of faces a and b: the midpoint segments' ends.
shared vec3 sh_ca[64];
shared vec3 sh_cb[64];
// The triangle's midpoint-segment test (shafts.rs: SegmentTest).
shared vec3 sh_seg_c[3];
shared vec3 sh_seg_m[3];
shared vec3 sh_seg_n;
shared float sh_seg_n2;
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

// The separations of axis l (projection interval [t0, t1], L1 norm l1) from face `face`'s
// patches: side 0, side 1, per u, per v (PairAxes::pair_axes).
void face_seps(uint face, dvec3 l, double l1, double t0, double t1, out double s0, out double s1,
               out double du, out double dv) {
    uint j = BAKE_FACE_AXIS[face], ua = BAKE_FACE_U[face], va = BAKE_FACE_V[face];
    double plane = double(face % 2u);
    precise double k = l[j] * plane + (l[ua] + l[va]) * P.half_s;
    precise double r = (abs(l[ua]) + abs(l[va])) * P.half_s + P.margin * l1;
    precise double a = k - r - t1;
    precise double b = t0 - k - r;
    precise double pu = l[ua] * P.s;
    precise double pv = l[va] * P.s;
    s0 = a;
    s1 = b;
    du = pu;
    dv = pv;
}

void main() {
    uint ci = gl_WorkGroupID.x, pair = gl_WorkGroupID.y, tid = gl_LocalInvocationID.x;
    BakeCell c = cells[ci];
    uint fa = BAKE_PAIR_A[pair], fb = BAKE_PAIR_B[pair];
    uint n = P.n, n2 = P.n2, n4 = P.n4;
    for (uint w = tid; w < 128u; w += 64u) {
        sh_bits[w] = 0u;
    }
    if (tid < n2) {
        sh_ca[tid] = patch_centre(fa, tid, c);
        sh_cb[tid] = patch_centre(fb, tid, c);
    }
    if (tid == 0u) {
        sh_tests = 0u;
    }
    dvec3 cmin = dvec3(c.gx, c.gy, c.gz);
    uint ends_base = ci * P.shafts * 2u;
    for (uint li = 0u; li < c.tri_count; ++li) {
        uint t = cell_tris[c.tri_first + li];
        barrier();
        if (tid < 13u) {
            precise dvec3 v0 = dvec3(local_corners[9u * t], local_corners[9u * t + 1u], local_corners[9u * t + 2u]) - cmin;
            precise dvec3 v1 = dvec3(local_corners[9u * t + 3u], local_corners[9u * t + 4u], local_corners[9u * t + 5u]) - cmin;
            precise dvec3 v2 = dvec3(local_corners[9u * t + 6u], local_corners[9u * t + 7u], local_corners[9u * t + 8u]) - cmin;
            dvec3 l = axis_of(tid, v0, v1, v2);
            precise double l1 = abs(l.x) + abs(l.y) + abs(l.z);
            precise double p0 = ddot_glam(l, v0);
            precise double p1 = ddot_glam(l, v1);
            precise double p2 = ddot_glam(l, v2);
            double t0 = min(min(p0, p1), p2);
            double t1 = max(max(p0, p1), p2);
            double s0, s1, du, dv;
            face_seps(fa, l, l1, t0, t1, s0, s1, du, dv);
            sh_ax[tid][0] = s0;
            sh_ax[tid][1] = s1;
            sh_ax[tid][2] = du;
            sh_ax[tid][3] = dv;
            face_seps(fb, l, l1, t0, t1, s0, s1, du, dv);
            sh_ax[tid][4] = s0;
            sh_ax[tid][5] = s1;
            sh_ax[tid][6] = du;
            sh_ax[tid][7] = dv;
        } else if (tid == 13u && P.records != 0u) {
            uint b = 20u * t;
            vec3 a = vec3(tri_data[b], tri_data[b + 1u], tri_data[b + 2u]);
            vec3 bb = vec3(tri_data[b + 3u], tri_data[b + 4u], tri_data[b + 5u]);
            vec3 cc = vec3(tri_data[b + 6u], tri_data[b + 7u], tri_data[b + 8u]);
            precise vec3 e01 = bb - a;
            precise vec3 e02 = cc - a;
            precise vec3 e12 = cc - bb;
            precise vec3 e20 = a - cc;
            vec3 nn = cross_glam(e01, e02);
            sh_seg_c[0] = a;
            sh_seg_c[1] = bb;
            sh_seg_c[2] = cc;
            sh_seg_n = nn;
            sh_seg_n2 = dot_glam(nn, nn);
            sh_seg_m[0] = cross_glam(nn, e01);
            sh_seg_m[1] = cross_glam(nn, e12);
            sh_seg_m[2] = cross_glam(nn, e20);
        }
        barrier();
        if (tid < n2) {
            double u = double(tid / n), v = double(tid % n);
            uint at_a = 0u, at_b = 0u;
            for (uint i = 0u; i < 13u; ++i) {
                precise double ta = u * sh_ax[i][2] + v * sh_ax[i][3];
                precise double a0 = sh_ax[i][0] + ta;
                precise double a1 = sh_ax[i][1] - ta;
                sh_sa[tid][i] = a0;
                sh_sa[tid][13u + i] = a1;
                at_a |= uint(a0 > 0.0) << i | uint(a1 > 0.0) << (13u + i);
                precise double tb = u * sh_ax[i][6] + v * sh_ax[i][7];
                precise double b0 = sh_ax[i][4] + tb;
                precise double b1 = sh_ax[i][5] - tb;
                sh_sb[tid][i] = b0;
                sh_sb[tid][13u + i] = b1;
                at_b |= uint(b0 > 0.0) << i | uint(b1 > 0.0) << (13u + i);
            }
            sh_at_a[tid] = at_a;
            sh_at_b[tid] = at_b;
        }
        barrier();
        double kmin = keys[(c.tri_first + li) * 30u + pair];
        double kmax = keys[(c.tri_first + li) * 30u + 15u + pair];
        uint tested = 0u;
        for (uint k = tid; k < n4; k += 64u) {
            uint pa = k / n2, pb = k % n2;
            uint lower = sh_at_a[pa], upper = sh_at_b[pb];
            if ((lower & upper) != 0u) {
                continue;
            }
            tested += 1u;
            bool met = lower == 0u || upper == 0u;
            if (!met) {
                // Roots as fractions num/den (den > 0), as PairAxes::shafts_among compares them.
                double lo_n = 0.0, lo_d = 1.0, hi_n = 1.0, hi_d = 1.0;
                uint m = lower;
                while (m != 0u) {
                    uint cc = findLSB(m);
                    m &= m - 1u;
                    double a = sh_sa[pa][cc], b = sh_sb[pb][cc];
                    precise double den = a - b;
                    precise double x = a * lo_d;
                    precise double y = lo_n * den;
                    if (x > y) {
                        lo_n = a;
                        lo_d = den;
                    }
                }
                m = upper;
                while (m != 0u) {
                    uint cc = findLSB(m);
                    m &= m - 1u;
                    double a = sh_sa[pa][cc], b = sh_sb[pb][cc];
                    precise double num = -a;
                    precise double den = b - a;
                    precise double x = num * hi_d;
                    precise double y = hi_n * den;
                    if (x < y) {
                        hi_n = num;
                        hi_d = den;
                    }
                }
                precise double x = lo_n * hi_d;
                precise double y = hi_n * lo_d;
                met = x <= y;
            }
            if (!met) {
                continue;
            }
            uint bit = 1u << (k & 31u);
            bool first = (atomicOr(sh_bits[k >> 5u], bit) & bit) == 0u;
            if (P.records == 0u) {
                continue;
            }
            uint e = ends_base + 2u * (pair * n4 + k);
            End front, back;
            if (first) {
                front = End(0.0, NONE, 0.0, 0.0, 0.0, NONE, 0u);
                back = front;
            } else {
                front = ends[e];
                back = ends[e + 1u];
            }
            // The midpoint segment (SegmentTest::hit_if), where its crossing is nearer either end.
            vec3 o = sh_ca[pa], d_end = sh_cb[pb];
            precise vec3 d = d_end - o;
            precise float denom = dot_glam(sh_seg_n, d);
            if (denom != 0.0 && sh_seg_n2 != 0.0) {
                precise vec3 co = sh_seg_c[0] - o;
                precise float num = dot_glam(sh_seg_n, co);
                float th = fdiv(num, denom);
                bool wanted = front.hit == NONE || th < front.t || back.hit == NONE || th > back.t;
                if (th >= 0.0 && th <= 1.0 && wanted) {
                    precise vec3 p = o + d * th;
                    precise vec3 pa0 = p - sh_seg_c[0];
                    precise vec3 pb0 = p - sh_seg_c[1];
                    precise vec3 pc0 = p - sh_seg_c[2];
                    precise float w0 = dot_glam(sh_seg_m[0], pa0);
                    precise float w1 = dot_glam(sh_seg_m[1], pb0);
                    precise float w2 = dot_glam(sh_seg_m[2], pc0);
                    if (w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0) {
                        float hu = fdiv(w2, sh_seg_n2), hv = fdiv(w0, sh_seg_n2);
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
            if (front.local_tri == NONE || !(kmin >= front.key)) {
                front.key = kmin;
                front.local_tri = li;
            }
            if (back.local_tri == NONE || !(kmax <= back.key)) {
                back.key = kmax;
                back.local_tri = li;
            }
            ends[e] = front;
            ends[e + 1u] = back;
        }
        if (tested != 0u) {
            atomicAdd(sh_tests, tested);
        }
    }
    barrier();
    // The pair's bits into the cell's words (pair-local bit k is shaft pair·n⁴ + k).
    uint wps = (P.shafts + 31u) / 32u;
    uint first_bit = pair * n4;
    for (uint w = tid; w * 32u < n4; w += 64u) {
        uint word = sh_bits[w];
        if (word == 0u) {
            continue;
        }
        uint g = first_bit + 32u * w;
        uint gw = ci * wps + g / 32u, off = g % 32u;
        atomicOr(bits[gw], word << off);
        if (off != 0u) {
            atomicOr(bits[gw + 1u], word >> (32u - off));
        }
    }
    if (tid == 0u) {
        tests[ci * 15u + pair] = sh_tests;
    }
}
