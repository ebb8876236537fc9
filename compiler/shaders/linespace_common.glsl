// The line-space bake on the GPU (compiler/src/bake/linespace/gpu.rs): the data both kernels
// share. Every floating-point result that decides a bit or a record is `precise` (no fused
// multiply-adds) and follows the CPU bake's arithmetic operation for operation
// (geometry.rs, shafts.rs, format's PnmtLayout::encode), so the two bakes agree bit for bit;
// single-precision divisions are taken in double precision and rounded once, which gives the
// correctly rounded quotient the CPU computes (a double quotient of two floats rounds to the
// nearest float without a double-rounding error).

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "bake_layout.glsl"

// (i + 1/2)/n: the patch centres' coordinates on a face.
double centre_coord(BakeParams p, uint i) {
    return i < 4u ? p.centre_lo[i] : p.centre_hi[i - 4u];
}

// One end of a shaft while its triangles fill it: the nearest hit of its midpoint segment from
// that end (`hit` the global triangle, NONE if none yet) and the fallback (the cell-local
// triangle reaching furthest towards that end, NONE before the first fill).
struct End {
    float t;
    uint hit;
    float u;
    float v;
    double key;
    uint local_tri;
};

// What the search leaves of an end for the records (3 words): the hit triangle, or the fallback
// as FALLBACK | its cell-local number; then the hit's barycentrics u and v (their bits).
const uint FALLBACK = 0x80000000u;

const uint NONE = 0xffffffffu;

// A float quotient, correctly rounded (see the top of this file).
precise float fdiv(float a, float b) {
    return float(double(a) / double(b));
}

// glam's cross product, term for term.
precise vec3 cross_glam(vec3 a, vec3 b) {
    precise float x = a.y * b.z - b.y * a.z;
    precise float y = a.z * b.x - b.z * a.x;
    precise float z = a.x * b.y - b.x * a.y;
    return vec3(x, y, z);
}

precise float dot_glam(vec3 a, vec3 b) {
    precise float d = a.x * b.x + a.y * b.y + a.z * b.z;
    return d;
}

precise dvec3 dcross_glam(dvec3 a, dvec3 b) {
    precise double x = a.y * b.z - b.y * a.z;
    precise double y = a.z * b.x - b.z * a.x;
    precise double z = a.x * b.y - b.x * a.y;
    return dvec3(x, y, z);
}

precise double ddot_glam(dvec3 a, dvec3 b) {
    precise double d = a.x * b.x + a.y * b.y + a.z * b.z;
    return d;
}

#ifdef KILN_BAKE_TRI_BINDING
// Per global triangle: world corners (9 floats), vertex normals (9), material (a whole float), padding.
layout(std430, set = 0, binding = KILN_BAKE_TRI_BINDING) readonly buffer TrisB { float tri_data[]; };

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
uvec4 encode(dvec3 position, vec3 normal, uint material, BakeCell c, uint layout_code) {
    dvec3 cmin = dvec3(c.wx, c.wy, c.wz);
    double steps = layout_code == BAKE_PNMT_FULL ? 65535.0 : 1023.0;
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
    float snorm = layout_code == BAKE_PNMT_FULL ? 32767.0 : 1023.0;
    int s[2];
    for (uint k = 0u; k < 2u; ++k) {
        float x = isnan(e[k]) ? e[k] : min(max(e[k], -1.0), 1.0);
        precise float y = x * snorm;
        s[k] = round_signed(y);
    }
    uint m = material;
    if (layout_code == BAKE_PNMT_FULL) {
        return uvec4(q[0] | q[1] << 16, q[2] | m << 16, (uint(s[0]) & 0xffffu) | (uint(s[1]) & 0xffffu) << 16, 0u);
    }
    uint s0 = uint(s[0] + 1023), s1 = uint(s[1] + 1023);
    return uvec4(q[0] | q[1] << 10 | q[2] << 20 | (m >> 10) << 30, s0 | s1 << 11 | (m & 0x3ffu) << 22, 0u, 0u);
}

// shafts.rs's hit_record.
uvec4 hit_record(uint t, float u, float v, BakeCell c, uint layout_code) {
    precise float w = 1.0 - u - v;
    precise vec3 p = tri_vec(t, 0u) * w + tri_vec(t, 1u) * u + tri_vec(t, 2u) * v;
    uint material = uint(tri_data[20u * t + 18u]);
    return encode(dvec3(p), shading_normal(t, u, v), material, c, layout_code);
}

#endif
