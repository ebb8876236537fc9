// Ray traversal of the baked compressed wide BVH (format/src/sections/bvh.rs) in compute
// shaders, mirroring the CPU query in format/src/query: the same watertight triangle test
// (Woop et al. 2013, with its double-precision fallback on edges) and conservative box tests, so
// that a triangle the brute-force test hits is never culled and the hits equal the CPU's up to
// ties in distance. Traversal order follows Ylitie et al. (HPG 2017): a stack of node groups
// (child base index + hit mask), children visited in the order of the ray's octant.
//
// The includer declares, before including this file:
//   layout(std430) readonly buffer BvhNodes { uvec4 bvh_nodes[]; };   // 5 uvec4 per node
//   layout(std430) readonly buffer BvhTriangles { vec4 bvh_tris[]; }; // 3 vec4 per triangle, leaf order
// and defines BVH_STACK (stack entries; the reader rejects trees deeper than 32). Defining
// BVH_ALPHA_TEST before the include makes traversal call `bool bvh_alpha_test(uint triangle,
// float u, float v)` on every candidate hit and skip it when that returns false (alpha masks).
#ifndef KILN_TRAVERSE_GLSL
#define KILN_TRAVERSE_GLSL

#ifndef BVH_STACK
#define BVH_STACK 32
#endif

const float GAMMA3 = 3.0 * 5.9604645e-8 / (1.0 - 3.0 * 5.9604645e-8);
const float NO_HIT = 3.402823e38;

struct TraceRay {
    vec3 origin;
    float tmin;
    vec3 direction;
    float tmax;
    vec3 inv_direction;
    uint octant_inv4;
    ivec3 k;        // watertight test axes: k.z dominant
    vec3 shear;
};

struct TraceHit {
    float t;        // NO_HIT when nothing was hit
    uint triangle;
    float u;        // barycentric weight of corner 1
    float v;        // barycentric weight of corner 2
};

TraceRay make_ray(vec3 origin, vec3 direction, float tmin, float tmax) {
    TraceRay r;
    r.origin = origin;
    r.direction = direction;
    r.tmin = tmin;
    r.tmax = tmax;
    // A zero component gets a huge finite reciprocal instead of infinity, so that a plane
    // through the origin gives 0 rather than NaN; the slab test stays conservative.
    r.inv_direction = vec3(
        direction.x != 0.0 ? 1.0 / direction.x : (direction.x >= 0.0 ? 1e38 : -1e38),
        direction.y != 0.0 ? 1.0 / direction.y : (direction.y >= 0.0 ? 1e38 : -1e38),
        direction.z != 0.0 ? 1.0 / direction.z : (direction.z >= 0.0 ? 1e38 : -1e38));
    uint octant = (direction.x < 0.0 ? 1u : 0u) | (direction.y < 0.0 ? 2u : 0u) | (direction.z < 0.0 ? 4u : 0u);
    r.octant_inv4 = (7u - octant) * 0x01010101u;
    vec3 a = abs(direction);
    int kz = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
    int kx = (kz + 1) % 3;
    int ky = (kx + 1) % 3;
    if (direction[kz] < 0.0) {
        int s = kx; kx = ky; ky = s;
    }
    r.k = ivec3(kx, ky, kz);
    float dz = direction[kz];
    r.shear = vec3(direction[kx] / dz, direction[ky] / dz, 1.0 / dz);
    return r;
}

// Moves a hit point off its surface along the geometric normal n (pointing to the side the new
// ray leaves into) by a few ulps of each coordinate (Wächter and Binder, Ray Tracing Gems ch. 6),
// as format/src/query/mod.rs's offset_origin: robust at every scale, unlike a fixed epsilon.
vec3 offset_ray_origin(vec3 p, vec3 n) {
    const float ORIGIN = 1.0 / 32.0;
    const float FLOAT_SCALE = 1.0 / 65536.0;
    const float INT_SCALE = 256.0;
    ivec3 of = ivec3(n * INT_SCALE);
    vec3 pi = intBitsToFloat(floatBitsToInt(p) + mix(of, -of, lessThan(p, vec3(0.0))));
    return mix(pi, p + FLOAT_SCALE * n, lessThan(abs(p), vec3(ORIGIN)));
}

// Watertight ray–triangle test; accepts tmin <= t < tmax. Both faces are hit.
bool intersect_triangle(TraceRay r, vec3 p0, vec3 p1, vec3 p2, float tmax, out vec3 tuv) {
    // `precise` keeps each product rounded on its own (no fused multiply-add), as on the CPU:
    // neighbours sharing an edge must compute the same edge function.
    precise vec3 a = p0 - r.origin;
    precise vec3 b = p1 - r.origin;
    precise vec3 c = p2 - r.origin;
    precise float ax = a[r.k.x] - r.shear.x * a[r.k.z];
    precise float ay = a[r.k.y] - r.shear.y * a[r.k.z];
    precise float bx = b[r.k.x] - r.shear.x * b[r.k.z];
    precise float by = b[r.k.y] - r.shear.y * b[r.k.z];
    precise float cx = c[r.k.x] - r.shear.x * c[r.k.z];
    precise float cy = c[r.k.y] - r.shear.y * c[r.k.z];
    precise float u = cx * by - cy * bx;
    precise float v = ax * cy - ay * cx;
    precise float w = bx * ay - by * ax;
    if (u == 0.0 || v == 0.0 || w == 0.0) {
        u = float(double(cx) * double(by) - double(cy) * double(bx));
        v = float(double(ax) * double(cy) - double(ay) * double(cx));
        w = float(double(bx) * double(ay) - double(by) * double(ax));
    }
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) {
        return false;
    }
    precise float det = u + v + w;
    if (det == 0.0 || isinf(det) || isnan(det)) {
        return false;
    }
    precise float az = r.shear.z * a[r.k.z];
    precise float bz = r.shear.z * b[r.k.z];
    precise float cz = r.shear.z * c[r.k.z];
    precise float t_scaled = u * az + v * bz + w * cz;
    precise float inv = 1.0 / det;
    precise float t = t_scaled * inv;
    if (!(t >= r.tmin && t < tmax)) {
        return false;
    }
    tuv = vec3(t, v * inv, w * inv);
    return true;
}

uint byte_of(uvec2 word, uint i) {
    return ((i < 4u ? word.x : word.y) >> ((i & 3u) * 8u)) & 0xffu;
}

// Slab tests of a node's eight children; returns the hit mask (Ylitie's encoding: internal
// children at bits 24.. permuted by the ray's octant, leaf triangles at their offsets).
uint intersect_children(TraceRay r, uint node, float tmax, out uvec2 bases, out uint imask) {
    uvec4 n0 = bvh_nodes[node * 5u];
    uvec4 n1 = bvh_nodes[node * 5u + 1u];
    uvec4 n2 = bvh_nodes[node * 5u + 2u];
    uvec4 n3 = bvh_nodes[node * 5u + 3u];
    uvec4 n4 = bvh_nodes[node * 5u + 4u];
    vec3 p = uintBitsToFloat(n0.xyz);
    vec3 s = vec3(uintBitsToFloat((n0.w & 0xffu) << 23), uintBitsToFloat(((n0.w >> 8) & 0xffu) << 23),
                  uintBitsToFloat(((n0.w >> 16) & 0xffu) << 23));
    imask = n0.w >> 24;
    bases = n1.xy;
    // Decoding p + s·q rounds once; widening every plane by at least one ulp of the node's
    // largest coordinate keeps the decoded boxes around the exact ones (cheaper than nextafter
    // per plane, and as conservative).
    vec3 widen = (abs(p) + s * 255.0) * 1.1920929e-7 + 1e-37;
    uint hitmask = 0u;
    for (uint i = 0u; i < 8u; i++) {
        uint meta = byte_of(n1.zw, i);
        if (meta == 0u) {
            continue;
        }
        vec3 lo = p + s * vec3(float(byte_of(n2.xy, i)), float(byte_of(n3.xy, i)), float(byte_of(n4.xy, i))) - widen;
        vec3 hi = p + s * vec3(float(byte_of(n2.zw, i)), float(byte_of(n3.zw, i)), float(byte_of(n4.zw, i))) + widen;
        vec3 t0 = (lo - r.origin) * r.inv_direction;
        vec3 t1 = (hi - r.origin) * r.inv_direction;
        vec3 tn = min(t0, t1);
        vec3 tf = max(t0, t1);
        float enter = max(max(tn.x, tn.y), max(tn.z, r.tmin));
        float exit = min(min(tf.x, tf.y), tf.z) * (1.0 + 2.0 * GAMMA3);
        exit = min(exit, tmax);
        if (enter <= exit) {
            uint bits = meta >> 5;
            uint index = meta & 31u;
            if ((meta & 0xe0u) == 0x20u && index >= 24u) {
                // Internal child: slot (index − 24) is visited in the ray's octant order.
                index = 24u + ((index - 24u) ^ (r.octant_inv4 & 7u));
                bits = 1u;
            }
            hitmask |= bits << index;
        }
    }
    return hitmask;
}

// Closest hit (any = false) or any hit (any = true) in [tmin, tmax).
TraceHit trace(TraceRay r, bool any) {
    TraceHit best = TraceHit(NO_HIT, 0xffffffffu, 0.0, 0.0);
    float tmax = r.tmax;
    uvec2 stack[BVH_STACK];
    int sp = 0;
    // Node group: (child base index, hit mask << 24 | imask). The root is the only child of an
    // imaginary group with base 0, one hit bit and an empty imask, so it decodes to node 0.
    uvec2 node_group = uvec2(0u, 0x80000000u);
    uvec2 triangle_group = uvec2(0u);
    while (true) {
        if (node_group.y > 0x00ffffffu) {
            uint hits = node_group.y;
            uint bit = uint(findMSB(hits));
            node_group.y &= ~(1u << bit);
            if (node_group.y > 0x00ffffffu) {
                if (sp >= BVH_STACK) {
                    // Cannot happen for files the reader accepts (depth ≤ 32).
                    break;
                }
                stack[sp++] = node_group;
            }
            uint slot = (bit - 24u) ^ (r.octant_inv4 & 7u);
            uint child = node_group.x + uint(bitCount(node_group.y & 0xffu & ~(0xffffffffu << slot)));
            uvec2 bases;
            uint imask;
            uint hitmask = intersect_children(r, child, tmax, bases, imask);
            node_group = uvec2(bases.x, (hitmask & 0xff000000u) | imask);
            triangle_group = uvec2(bases.y, hitmask & 0x00ffffffu);
        } else {
            triangle_group = node_group;
            node_group = uvec2(0u);
        }
        while (triangle_group.y != 0u) {
            uint bit = uint(findLSB(triangle_group.y));
            triangle_group.y &= ~(1u << bit);
            uint tri = triangle_group.x + bit;
            vec3 tuv;
            if (intersect_triangle(r, bvh_tris[tri * 3u].xyz, bvh_tris[tri * 3u + 1u].xyz, bvh_tris[tri * 3u + 2u].xyz, tmax, tuv)) {
#ifdef BVH_ALPHA_TEST
                if (!bvh_alpha_test(tri, tuv.y, tuv.z)) {
                    continue;
                }
#endif
                best = TraceHit(tuv.x, tri, tuv.y, tuv.z);
                tmax = tuv.x;
                if (any) {
                    return best;
                }
            }
        }
        if (node_group.y <= 0x00ffffffu) {
            if (sp == 0) {
                break;
            }
            node_group = stack[--sp];
        }
    }
    return best;
}

#endif
