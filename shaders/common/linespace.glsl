// Queries through the voxel grid and line space (seed 004), mirroring the CPU queries of
// format/src/linespace/query.rs step for step (a test holds them to it): a 3D-DDA over the cells,
// in each non-empty cell the shaft the ray's line passes through, then
//   - ls_any_binary:      conservative any hit from the shaft bits alone;
//   - ls_occluded_binary: the bits, with exact triangle tests in filled cells near the ray's
//                         ends (no self-shadowing, no "voxel offset") or in every filled cell
//                         (the exact answer, the bits as a skip test); ls_occluded and
//                         ls_occluded_dir wrap it for shadow rays from a surface point;
//   - ls_trace_candidates: closest or any hit through the candidate lists (exact);
//   - ls_pnmt_hit:        the approximate hit stored for the shaft (PNMT), with the self-hit rule;
//   - ls_preillum:        the pre-illuminated radiance of a shaft's front or back hit.
//
// Precision: the CPU walks the grid in double precision, this in single, relative to the grid's
// origin in cell units. Cells and shafts were widened by the grid margin (8 single-precision ulps
// of the scene's extent) when baked, which absorbs the difference except for rays that pass
// within a few ulps of a cell corner or a patch border; there the two may pick neighbouring
// shafts (the test bounds how often and checks that it happens only there).
//
// The includer defines LS_BINDING (the first of 9 bindings in set 0: the GpuGrid uniform, then
// LS_MAX_CHUNKS storage buffers of words) and includes traverse.glsl first (TraceRay, TraceHit,
// intersect_triangle, bvh_tris: triangle corners by file triangle number, which is what the cell
// lists and candidate entries name).
#ifndef KILN_LINESPACE_GLSL
#define KILN_LINESPACE_GLSL

#include "shaft.glsl"

layout(set = 0, binding = LS_BINDING) uniform LsGrid { GpuGrid grid; };
layout(set = 0, binding = LS_BINDING + 1, std430) readonly buffer LsChunk0 { uint ls_chunk0[]; };
layout(set = 0, binding = LS_BINDING + 2, std430) readonly buffer LsChunk1 { uint ls_chunk1[]; };
layout(set = 0, binding = LS_BINDING + 3, std430) readonly buffer LsChunk2 { uint ls_chunk2[]; };
layout(set = 0, binding = LS_BINDING + 4, std430) readonly buffer LsChunk3 { uint ls_chunk3[]; };
layout(set = 0, binding = LS_BINDING + 5, std430) readonly buffer LsChunk4 { uint ls_chunk4[]; };
layout(set = 0, binding = LS_BINDING + 6, std430) readonly buffer LsChunk5 { uint ls_chunk5[]; };
layout(set = 0, binding = LS_BINDING + 7, std430) readonly buffer LsChunk6 { uint ls_chunk6[]; };
layout(set = 0, binding = LS_BINDING + 8, std430) readonly buffer LsChunk7 { uint ls_chunk7[]; };

// Word i of the concatenated arrays (see player/src/scene/linespace.rs). A switch over separate
// bindings rather than an array of buffers: dynamically indexed buffer arrays need a device
// feature, this needs none.
uint ls_word(uint i) {
    uint j = i & ((1u << grid.chunk_shift) - 1u);
    switch (i >> grid.chunk_shift) {
        case 0u: return ls_chunk0[j];
        case 1u: return ls_chunk1[j];
        case 2u: return ls_chunk2[j];
        case 3u: return ls_chunk3[j];
        case 4u: return ls_chunk4[j];
        case 5u: return ls_chunk5[j];
        case 6u: return ls_chunk6[j];
        default: return ls_chunk7[j];
    }
}

uint ls_cell_offset(uint c) { return ls_word(grid.bases_a.x + c); }
uint ls_cell_triangle(uint k) { return ls_word(grid.bases_a.y + k); }
uint ls_slot(uint c) { return ls_word(grid.bases_a.z + c); }
uint ls_candidate_offset(uint rank) { return ls_word(grid.bases_b.y + rank); }
uint ls_candidate(uint k) { return ls_word(grid.bases_b.z + k); }

// Filled-shaft rank of (slot, shaft), or -1 for an empty shaft.
int ls_rank(uint slot, uint shaft) {
    uint w = slot * grid.words_per_slot + shaft / 32u;
    uint bit = 1u << (shaft % 32u);
    uint word = ls_word(grid.bases_a.w + w);
    if ((word & bit) == 0u) {
        return -1;
    }
    return int(ls_word(grid.bases_b.x + w) + uint(bitCount(word & (bit - 1u))));
}

bool ls_filled(uint slot, uint shaft) {
    uint w = slot * grid.words_per_slot + shaft / 32u;
    return (ls_word(grid.bases_a.w + w) & (1u << (shaft % 32u))) != 0u;
}

uint ls_cell_index(ivec3 c) {
    return uint(c.x) + grid.dims.x * (uint(c.y) + grid.dims.y * uint(c.z));
}

// ---------------------------------------------------------------- 3D-DDA (Amanatides and Woo)
// Over the cells of o + t d (cell units, relative to the grid origin) for t in [t0, t1]. A start
// exactly on a cell plane while moving down belongs to the lower cell, as on the CPU.
struct LsDda {
    vec3 o;
    vec3 d;
    ivec3 cell;
    ivec3 step;
    vec3 t_next;
    float t;
    float t_end;
    bool done;
};

float ls_boundary(LsDda s, int a) {
    if (s.step[a] > 0) {
        return (float(s.cell[a] + 1) - s.o[a]) / s.d[a];
    }
    if (s.step[a] < 0) {
        return (float(s.cell[a]) - s.o[a]) / s.d[a];
    }
    return 3.4e38;
}

LsDda ls_dda(vec3 origin, vec3 dir, float t0, float t1) {
    LsDda s;
    s.o = ((origin - grid.origin) - grid.origin_lo) * grid.inv_cell;
    s.d = dir * grid.inv_cell;
    vec3 dims = vec3(grid.dims);
    float lo = t0, hi = t1;
    for (int a = 0; a < 3; a++) {
        if (s.d[a] == 0.0) {
            if (s.o[a] < 0.0 || s.o[a] > dims[a]) {
                hi = -3.4e38;
            }
        } else {
            float ta = (0.0 - s.o[a]) / s.d[a], tb = (dims[a] - s.o[a]) / s.d[a];
            lo = max(lo, min(ta, tb));
            hi = min(hi, max(ta, tb));
        }
    }
    s.t = lo;
    s.t_end = hi;
    s.done = !(lo <= hi);
    s.cell = ivec3(0);
    s.step = ivec3(0);
    s.t_next = vec3(3.4e38);
    if (s.done) {
        return s;
    }
    vec3 p = s.o + s.d * lo;
    for (int a = 0; a < 3; a++) {
        int c = int(floor(p[a]));
        if (s.d[a] < 0.0 && p[a] == floor(p[a])) {
            c -= 1;
        }
        s.cell[a] = clamp(c, 0, int(grid.dims[a]) - 1);
        s.step[a] = s.d[a] > 0.0 ? 1 : (s.d[a] < 0.0 ? -1 : 0);
    }
    for (int a = 0; a < 3; a++) {
        s.t_next[a] = ls_boundary(s, a);
    }
    return s;
}

// The next cell: its coordinates, and where the line enters and leaves it (t_exit unclipped).
bool ls_dda_next(inout LsDda s, out ivec3 cell, out float t_enter, out float t_exit) {
    if (s.done) {
        return false;
    }
    int a = (s.t_next.x <= s.t_next.y && s.t_next.x <= s.t_next.z) ? 0 : (s.t_next.y <= s.t_next.z ? 1 : 2);
    float exit_t = s.t_next[a];
    cell = s.cell;
    t_enter = s.t;
    t_exit = exit_t;
    if (exit_t >= s.t_end) {
        s.done = true;
    } else {
        s.cell[a] += s.step[a];
        s.t = exit_t;
        s.t_next[a] = ls_boundary(s, a);
        if (s.cell[a] < 0 || s.cell[a] >= int(grid.dims[a])) {
            s.done = true;
        }
    }
    return true;
}

// ---------------------------------------------------------------- shaft lookup
struct LsShaft {
    uint shaft;
    bool front;     // the line runs from the pair's lower face to its higher face
    vec3 key_dir;   // n_b - n_a of the pair (outward normals)
    float key_lo;   // smallest key over the cell
};

vec3 ls_outward(uint face) {
    vec3 n = vec3(0.0);
    n[face / 2u] = (face % 2u) == 0u ? -1.0 : 1.0;
    return n;
}

// The shaft of the line o + t d (cell units, grid-relative) in `cell`; false when the line
// misses the cell (it may still pass within the margin: callers then test every triangle).
bool ls_lookup(ivec3 cell, vec3 o, vec3 d, out LsShaft l) {
    vec3 p = o - vec3(cell);
    int ea = -1, xa = -1;
    float near_t = 0.0, far_t = 0.0;
    for (int a = 0; a < 3; a++) {
        if (d[a] == 0.0) {
            continue;
        }
        float t0 = (0.0 - p[a]) / d[a], t1 = (1.0 - p[a]) / d[a];
        float n = min(t0, t1), f = max(t0, t1);
        // Ties go to the lower axis, as on the CPU.
        if (ea < 0 || n > near_t) {
            ea = a;
            near_t = n;
        }
        if (xa < 0 || f < far_t) {
            xa = a;
            far_t = f;
        }
    }
    if (ea < 0 || near_t > far_t) {
        return false;
    }
    uint entry_face = 2u * uint(ea) + (d[ea] < 0.0 ? 1u : 0u);
    uint exit_face = 2u * uint(xa) + (d[xa] > 0.0 ? 1u : 0u);
    uint n = grid.shaft_res;
    vec3 qe = p + d * near_t;
    vec3 qx = p + d * far_t;
    ivec2 ue = LS_FACE_UV[entry_face], ux = LS_FACE_UV[exit_face];
    uint pe = ls_patch(qe[ue.x], qe[ue.y], n);
    uint px = ls_patch(qx[ux.x], qx[ux.y], n);
    bool front;
    uint s = ls_shaft(entry_face, pe, exit_face, px, n, front);
    if (s == 0xFFFFFFFFu) {
        return false;
    }
    uint fa = front ? entry_face : exit_face;
    uint fb = front ? exit_face : entry_face;
    l.shaft = s;
    l.front = front;
    l.key_dir = ls_outward(fb) - ls_outward(fa);
    l.key_lo = min(l.key_dir.x, 0.0) + min(l.key_dir.y, 0.0) + min(l.key_dir.z, 0.0);
    return true;
}

// ---------------------------------------------------------------- exact tests in a cell
// Closest (or any) hit among the triangles of a cell's list in [first, last), below best.t.
void ls_test_triangle(TraceRay r, uint tri, inout TraceHit best) {
    vec3 tuv;
    float tmax = best.t == NO_HIT ? r.tmax : best.t;
    if (intersect_triangle(r, bvh_tris[3u * tri].xyz, bvh_tris[3u * tri + 1u].xyz, bvh_tris[3u * tri + 2u].xyz, tmax, tuv)) {
#ifdef BVH_ALPHA_TEST
        if (!bvh_alpha_test(tri, tuv.y, tuv.z)) {
            return;
        }
#endif
        best = TraceHit(tuv.x, tri, tuv.y, tuv.z);
    }
}

bool ls_cell_hit(TraceRay r, uint c, bool any, inout TraceHit best) {
    uint first = ls_cell_offset(c), last = ls_cell_offset(c + 1u);
    for (uint k = first; k < last; k++) {
        ls_test_triangle(r, ls_cell_triangle(k), best);
        if (any && best.t != NO_HIT) {
            return true;
        }
    }
    return best.t != NO_HIT;
}

// ---------------------------------------------------------------- binary
// Conservative: true if the ray passes through a filled shaft of any cell it meets in
// [tmin, tmax] (or through a non-empty cell its line misses). Never false when a triangle is hit.
bool ls_any_binary(vec3 origin, vec3 dir, float tmin, float tmax) {
    LsDda s = ls_dda(origin, dir, tmin, tmax);
    ivec3 cell;
    float t_in, t_out;
    while (ls_dda_next(s, cell, t_in, t_out)) {
        uint slot = ls_slot(ls_cell_index(cell));
        if (slot == LS_NO_SLOT) {
            continue;
        }
        LsShaft l;
        if (!ls_lookup(cell, s.o, s.d, l) || ls_filled(slot, l.shaft)) {
            return true;
        }
    }
    return false;
}

// Any hit among the triangles that can meet the ray in cell c: the shaft's candidate list when
// the candidates are uploaded (a fraction of the cell's triangles), else the cell's list. `l` is
// the shaft, if the line meets the cell (`has_shaft`; if not, the cell's list).
bool ls_shaft_hit(TraceRay r, uint c, uint slot, bool has_shaft, LsShaft l, inout TraceHit best) {
    int rank = grid.bases_b.z != LS_NO_BASE && has_shaft ? ls_rank(slot, l.shaft) : -1;
    if (rank < 0) {
        return ls_cell_hit(r, c, true, best);
    }
    uint first = ls_cell_offset(c);
    uint a = ls_candidate_offset(uint(rank)), b = ls_candidate_offset(uint(rank) + 1u);
    for (uint k = a; k < b; k++) {
        ls_test_triangle(r, ls_cell_triangle(first + ls_entry_local(ls_candidate(k))), best);
        if (best.t != NO_HIT) {
            return true;
        }
    }
    return false;
}

// Cells within this many cell edges of a ray's ends are tested exactly by ls_occluded_binary:
// a surface's own triangles fill the shafts of its neighbouring cells too, so a feeler leaving it
// at a shallow angle would otherwise be blocked by the surface it starts on (the thesis's "voxel
// offset" problem, which it solved by skipping the start voxel and lost shadows in corners).
const float LS_EXACT_REACH = 2.0;

// Any hit with exact triangle tests where the binary answer says "filled": in the cells within
// LS_EXACT_REACH cells of the ray's ends only (`exact_everywhere` false: conservative in between,
// seed 004's shadow feelers without their self-shadowing), or in every filled cell (exact).
bool ls_occluded_binary(TraceRay r, bool exact_everywhere) {
    LsDda s = ls_dda(r.origin, r.direction, r.tmin, r.tmax);
    float reach = LS_EXACT_REACH / length(s.d);  // in ray parameter units
    ivec3 cell;
    float t_in, t_out;
    while (ls_dda_next(s, cell, t_in, t_out)) {
        uint c = ls_cell_index(cell);
        uint slot = ls_slot(c);
        if (slot == LS_NO_SLOT) {
            continue;
        }
        LsShaft l;
        bool has_shaft = ls_lookup(cell, s.o, s.d, l);
        if (has_shaft && !ls_filled(slot, l.shaft)) {
            continue;
        }
        bool near_end = t_in <= r.tmin + reach || t_out >= r.tmax - reach;
        if (!exact_everywhere && !near_end) {
            return true;
        }
        TraceHit h = TraceHit(NO_HIT, 0u, 0.0, 0.0);
        if (ls_shaft_hit(r, c, slot, has_shaft, l, h)) {
            return true;
        }
    }
    return false;
}

// Whether the segment from `from`, on a surface of geometric normal `ng` (the side it leaves
// by), to `to` is blocked, through ls_occluded_binary: the origin offset and the end pulled back
// as scene.glsl's `occluded` does them, so that neither end's own surface blocks.
bool ls_occluded(vec3 from, vec3 ng, vec3 to, bool exact_everywhere) {
    vec3 o = offset_ray_origin(from, ng);
    vec3 d = to - o;
    float dist = length(d);
    return dist > 0.0 && ls_occluded_binary(make_ray(o, d / dist, 0.0, dist * (1.0 - 1e-5)), exact_everywhere);
}

// The same for the unbounded ray along `dir` (directional lights, the sky).
bool ls_occluded_dir(vec3 from, vec3 ng, vec3 dir, bool exact_everywhere) {
    return ls_occluded_binary(make_ray(offset_ray_origin(from, ng), dir, 0.0, 3.4e38), exact_everywhere);
}

// ---------------------------------------------------------------- candidates
// Closest hit (any = false) or any hit through the candidate lists: the brute-force answer up to
// ties in distance.
TraceHit ls_trace_candidates(TraceRay r, bool any) {
    TraceHit best = TraceHit(NO_HIT, 0xffffffffu, 0.0, 0.0);
    LsDda s = ls_dda(r.origin, r.direction, r.tmin, r.tmax);
    float margin_t = grid.margin / length(r.direction) * 2.0;
    ivec3 cell;
    float t_in, t_out;
    while (ls_dda_next(s, cell, t_in, t_out)) {
        if (best.t != NO_HIT && t_in > best.t + margin_t) {
            break;
        }
        uint c = ls_cell_index(cell);
        uint slot = ls_slot(c);
        if (slot == LS_NO_SLOT) {
            continue;
        }
        uint first = ls_cell_offset(c);
        LsShaft l;
        if (!ls_lookup(cell, s.o, s.d, l)) {
            if (ls_cell_hit(r, c, any, best) && any) {
                return best;
            }
            continue;
        }
        int rank = ls_rank(slot, l.shaft);
        if (rank < 0) {
            continue;
        }
        uint a = ls_candidate_offset(uint(rank)), b = ls_candidate_offset(uint(rank) + 1u);
        vec3 cell_o = s.o - vec3(cell);
        for (uint k = 0u; k < b - a; k++) {
            uint e = ls_candidate(l.front ? a + k : b - 1u - k);
            if (best.t != NO_HIT) {
                float key = dot(cell_o + s.d * best.t, l.key_dir);
                if (l.front && l.key_lo + float(ls_entry_key_min(e)) * (2.0 / 255.0) > key + grid.key_eps) {
                    break;
                }
                if (!l.front && l.key_lo + float(ls_entry_prefix_key_max(e)) * (2.0 / 255.0) < key - grid.key_eps) {
                    break;
                }
            }
            ls_test_triangle(r, ls_cell_triangle(first + ls_entry_local(e)), best);
            if (any && best.t != NO_HIT) {
                return best;
            }
        }
    }
    return best;
}

// ---------------------------------------------------------------- PNMT
struct LsRecord {
    vec3 position;
    vec3 normal;
    uint material;
    vec2 uv;
    float t;        // (position - origin) . dir / |dir|^2
    uint rank;      // filled-shaft rank (pre-illuminated records are found by it)
    bool front;     // which of the shaft's two records
};

// The first accepted PNMT record along the ray: its point within [tmin, tmax] and, when
// `origin_normal` is not zero (the geometric normal of the surface the ray leaves, on the side it
// leaves into), further than the quantisation step in front of that surface's plane.
bool ls_pnmt_hit(vec3 origin, vec3 dir, float tmin, float tmax, vec3 origin_normal, out LsRecord rec) {
    LsDda s = ls_dda(origin, dir, tmin, tmax);
    float d2 = dot(dir, dir);
    bool check_plane = dot(origin_normal, origin_normal) > 0.0;
    ivec3 cell;
    float t_in, t_out;
    while (ls_dda_next(s, cell, t_in, t_out)) {
        uint slot = ls_slot(ls_cell_index(cell));
        if (slot == LS_NO_SLOT) {
            continue;
        }
        LsShaft l;
        if (!ls_lookup(cell, s.o, s.d, l)) {
            continue;
        }
        int rank = ls_rank(slot, l.shaft);
        if (rank < 0) {
            continue;
        }
        uint words = LS_PNMT_WORDS[grid.pnmt_layout];
        uint base = grid.bases_b.w + words * (2u * uint(rank) + (l.front ? 0u : 1u));
        uint w1 = ls_word(base + 1u);
        vec3 local;
        uint material;
        if (!ls_pnmt_head(grid.pnmt_layout, ls_word(base), w1, local, material)) {
            continue;
        }
        // The record relative to the ray's origin, from grid coordinates: far from the world
        // origin, world positions in single precision would cancel to a few ulps of 1e5.
        vec3 rel = (vec3(cell) + local - s.o) * grid.cell;
        float t = dot(rel, dir) / d2;
        bool in_front = !check_plane || dot(rel, origin_normal) > grid.pnmt_step;
        if (t >= tmin && t <= tmax && in_front) {
            rec.position = origin + rel;
            uint w2 = words > 2u ? ls_word(base + 2u) : 0u;
            uint w3 = words > 3u ? ls_word(base + 3u) : 0u;
            vec2 oct;
            ls_pnmt_tail(grid.pnmt_layout, w1, w2, w3, oct, rec.uv);
            rec.normal = ls_oct_decode(oct);
            rec.material = material;
            rec.t = t;
            rec.rank = uint(rank);
            rec.front = l.front;
            return true;
        }
    }
    return false;
}

// Pre-illuminated radiance of a record's hit towards the ray (binary16 RGB, front then back).
vec3 ls_preillum(LsRecord rec) {
    uint base = grid.bases_c.x + 4u * rec.rank + (rec.front ? 0u : 2u);
    return vec3(unpackHalf2x16(ls_word(base)), unpackHalf2x16(ls_word(base + 1u)).x);
}

#endif
