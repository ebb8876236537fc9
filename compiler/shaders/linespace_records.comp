#version 460
// The line-space bake's PNMT records on the GPU: one workgroup per cell. Each filled shaft's
// front and back ends (left by linespace_search.comp) become records in the layout, written at
// the shaft's rank among the cell's filled shafts: a hit as shafts.rs's hit_record encodes it
// (format's PnmtLayout::encode, operation for operation), a fallback from the table the CPU
// made per (cell triangle, pair, end).
#extension GL_GOOGLE_include_directive : require
#include "linespace_common.glsl"

layout(local_size_x = 256) in;

layout(std430, set = 0, binding = 0) readonly buffer ParamsB { BakeParams P; };
layout(std430, set = 0, binding = 1) readonly buffer CellsB { BakeCell cells[]; };
// Per cell triangle, pair and end: the fallback record (P.words words).
layout(std430, set = 0, binding = 2) readonly buffer FallbacksB { uint fallbacks[]; };
layout(std430, set = 0, binding = 3) readonly buffer TrisB { float tri_data[]; };
layout(std430, set = 0, binding = 4) readonly buffer EndsB { End ends[]; };
layout(std430, set = 0, binding = 5) readonly buffer BitsB { uint bits[]; };
layout(std430, set = 0, binding = 6) writeonly buffer RecordsB { uint records[]; };

// Filled shafts before each bit word of the cell (words_per_slot(8) = 1,920 at most).
shared uint sh_rank[1920];

vec3 tri_vec(uint t, uint k) {
    uint b = 20u * t + 3u * k;
    return vec3(tri_data[b], tri_data[b + 1u], tri_data[b + 2u]);
}

bool usable(vec3 n) {
    return !any(isnan(n)) && !any(isinf(n)) && n != vec3(0.0);
}

// HitAttributes::normal of SceneAttributes (compiler/src/bake/linespace/mod.rs).
vec3 shading_normal(uint t, float u, float v) {
    precise float w = 1.0 - u - v;
    precise vec3 n = tri_vec(t, 3u) * w + tri_vec(t, 4u) * u + tri_vec(t, 5u) * v;
    if (usable(n)) {
        return n;
    }
    vec3 p = tri_vec(t, 0u), q = tri_vec(t, 1u), r = tri_vec(t, 2u);
    precise vec3 qp = q - p;
    precise vec3 rp = r - p;
    vec3 g = cross_glam(qp, rp);
    return usable(g) ? g : vec3(0.0, 0.0, 1.0);
}

// format's round_unsigned: halves away from zero, NaN 0.
uint round_unsigned(double x) {
    if (isnan(x)) {
        return 0u;
    }
    uint i = uint(x);
    precise double f = x - double(i);
    return i + uint(f >= 0.5);
}

// format's round_signed.
int round_signed(float x) {
    if (isnan(x)) {
        return 0;
    }
    int i = int(x);
    precise float f = x - float(i);
    return i + int(f >= 0.5) - int(f <= -0.5);
}

float sign_of(float v) {
    return v >= 0.0 ? 1.0 : -1.0;
}

// PnmtLayout::encode without texture coordinates (the GPU bake runs only where records store
// none, or the scene has none: binary16 zeros).
uvec4 encode(dvec3 position, vec3 normal, uint material, BakeCell c) {
    dvec3 cmin = dvec3(c.wx, c.wy, c.wz);
    double steps = P.layout_code == 0u ? 65535.0 : 1023.0;
    uint q[3];
    for (uint k = 0u; k < 3u; ++k) {
        precise double x = (position[k] - cmin[k]) * c.inv_cell;
        // DVec3::clamp: max then min, NaN giving the bound.
        double y = isnan(x) ? 0.0 : min(max(x, 0.0), 1.0);
        precise double z = y * steps;
        q[k] = round_unsigned(z);
    }
    precise float l1 = abs(normal.x) + abs(normal.y) + abs(normal.z);
    vec3 nn = vec3(fdiv(normal.x, l1), fdiv(normal.y, l1), fdiv(normal.z, l1));
    vec2 e = nn.xy;
    if (!(nn.z >= 0.0)) {
        precise float ex = (1.0 - abs(e.y)) * sign_of(e.x);
        precise float ey = (1.0 - abs(e.x)) * sign_of(e.y);
        e = vec2(ex, ey);
    }
    float snorm = P.layout_code == 0u ? 32767.0 : 1023.0;
    int s[2];
    for (uint k = 0u; k < 2u; ++k) {
        float x = isnan(e[k]) ? e[k] : min(max(e[k], -1.0), 1.0);
        precise float y = x * snorm;
        s[k] = round_signed(y);
    }
    uint m = material;
    if (P.layout_code == 0u) {
        return uvec4(q[0] | q[1] << 16, q[2] | m << 16, (uint(s[0]) & 0xffffu) | (uint(s[1]) & 0xffffu) << 16, 0u);
    }
    uint s0 = uint(s[0] + 1023), s1 = uint(s[1] + 1023);
    return uvec4(q[0] | q[1] << 10 | q[2] << 20 | (m >> 10) << 30, s0 | s1 << 11 | (m & 0x3ffu) << 22, 0u, 0u);
}

// shafts.rs's hit_record.
uvec4 hit_record(uint t, float u, float v, BakeCell c) {
    precise float w = 1.0 - u - v;
    precise vec3 p = tri_vec(t, 0u) * w + tri_vec(t, 1u) * u + tri_vec(t, 2u) * v;
    uint material = floatBitsToUint(tri_data[20u * t + 18u]);
    return encode(dvec3(p), shading_normal(t, u, v), material, c);
}

void main() {
    uint ci = gl_WorkGroupID.x, tid = gl_LocalInvocationID.x;
    BakeCell c = cells[ci];
    uint wps = (P.shafts + 31u) / 32u;
    for (uint w = tid; w < wps; w += 256u) {
        sh_rank[w] = bitCount(bits[ci * wps + w]);
    }
    barrier();
    if (tid == 0u) {
        uint sum = 0u;
        for (uint w = 0u; w < wps; ++w) {
            uint k = sh_rank[w];
            sh_rank[w] = sum;
            sum += k;
        }
    }
    barrier();
    for (uint s = tid; s < P.shafts; s += 256u) {
        uint word = bits[ci * wps + s / 32u], b = s % 32u;
        if ((word >> b & 1u) == 0u) {
            continue;
        }
        uint rank = sh_rank[s / 32u] + bitCount(word & ((1u << b) - 1u));
        uint pair = s / P.n4;
        uint out_at = (c.record_base + rank) * 2u * P.words;
        for (uint side = 0u; side < 2u; ++side) {
            End e = ends[ci * P.shafts * 2u + 2u * s + side];
            uvec4 r;
            if (e.hit != NONE) {
                r = hit_record(e.hit, e.u, e.v, c);
            } else {
                uint f = (((c.tri_first + e.local_tri) * 15u + pair) * 2u + side) * P.words;
                r = uvec4(fallbacks[f], fallbacks[f + 1u], P.words > 2u ? fallbacks[f + 2u] : 0u,
                          P.words > 3u ? fallbacks[f + 3u] : 0u);
            }
            for (uint k = 0u; k < P.words; ++k) {
                records[out_at + side * P.words + k] = r[k];
            }
        }
    }
}
