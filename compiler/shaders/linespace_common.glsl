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
    uint pad;
};

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
