#version 460
#extension GL_EXT_control_flow_attributes : require
// The reference path tracer: one unbiased sample per pixel per dispatch, accumulated.
//
// Paths: camera rays jittered over the pixel (box filter); at each vertex next-event estimation
// towards one emitter chosen in proportion to its power (analytic lights, emissive triangles),
// and a BRDF-sampled continuation; emitters the continuation hits (emissive triangles, rect
// lights) count with the power heuristic against the emitter sampling, delta lights by NEE
// alone. Russian roulette from the fourth vertex; `params.y` caps the length as a safety net.
// BRDF: glTF metallic-roughness (Lambert diffuse weighted by 1 − F, GGX with height-correlated
// Smith and Schlick F; α = roughness²) sampled with cosine-weighted diffuse and GGX visible
// normals (Heitz 2018), or pure Lambert for diffuse-only materials. All surfaces are two-sided
// for reflection; emission leaves the front face only unless the material is double-sided.
// Textures: mip 0, bilinear, from a texel buffer (portable: no descriptor indexing needed).
#include "../common/layout.glsl"
#include "../common/packing.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Constants { ReferenceConstants rc; };
layout(set = 0, binding = 1, std430) readonly buffer BvhNodes { uvec4 bvh_nodes[]; };
layout(set = 0, binding = 2, std430) readonly buffer BvhTriangles { vec4 bvh_tris[]; };
layout(set = 0, binding = 3, std430) readonly buffer Vertices { float vertex_data[]; };   // 6 floats each
layout(set = 0, binding = 4, std430) readonly buffer Uvs { vec2 uvs[]; };
layout(set = 0, binding = 5, std430) readonly buffer Indices { uint indices[]; };        // leaf order
layout(set = 0, binding = 6, std430) readonly buffer TriMaterials { uint tri_materials[]; };
layout(set = 0, binding = 7, std430) readonly buffer Materials { GpuMaterialLayout materials[]; };
layout(set = 0, binding = 8, std430) readonly buffer Lights { GpuLight lights[]; };
layout(set = 0, binding = 9, std430) readonly buffer Emitters { GpuEmitter emitters[]; };
layout(set = 0, binding = 10, std430) readonly buffer TriEmitters { int tri_emitter[]; };
layout(set = 0, binding = 11, std430) readonly buffer Texels { uint texels[]; };
layout(set = 0, binding = 12, std430) readonly buffer Textures { GpuTexture textures[]; };
layout(set = 0, binding = 13, rgba32f) uniform image2D accumulation;
// Index of this sample (0 first): 0 overwrites the accumulation, later ones add to it.
layout(push_constant) uniform Sample { uint sample_index; };

const float PI = 3.14159265358979;

// ---------------------------------------------------------------- random numbers (PCG)
uint rng;
uint pcg() {
    uint s = rng;
    rng = s * 747796405u + 2891336453u;
    uint w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}
float rnd() {
    return float(pcg() >> 8) * (1.0 / 16777216.0);
}
uint hash(uint x) {
    x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
    return x;
}

// ---------------------------------------------------------------- textures
int wrap(int i, int n, uint mode) {
    if (mode == 2u) {
        return clamp(i, 0, n - 1);
    }
    if (mode == 1u) {
        int m = ((i % (2 * n)) + 2 * n) % (2 * n);
        return m < n ? m : 2 * n - 1 - m;
    }
    return ((i % n) + n) % n;
}

vec4 texel(GpuTexture t, int x, int y) {
    x = wrap(x, int(t.width), (t.flags >> TEXTURE_WRAP_U_SHIFT) & 3u);
    y = wrap(y, int(t.height), (t.flags >> TEXTURE_WRAP_V_SHIFT) & 3u);
    vec4 c = unpackUnorm4x8(texels[t.offset + uint(y) * t.width + uint(x)]);
    if ((t.flags & TEXTURE_SRGB) != 0u) {
        c.rgb = srgb_to_linear(c.rgb);
    }
    return c;
}

vec4 sample_texture(uint index, vec2 uv) {
    GpuTexture t = textures[index];
    vec2 x = uv * vec2(t.width, t.height);
    if ((t.flags & TEXTURE_LINEAR) == 0u) {
        return texel(t, int(floor(x.x)), int(floor(x.y)));
    }
    x -= 0.5;
    ivec2 i = ivec2(floor(x));
    vec2 f = x - vec2(i);
    return mix(mix(texel(t, i.x, i.y), texel(t, i.x + 1, i.y), f.x), mix(texel(t, i.x, i.y + 1), texel(t, i.x + 1, i.y + 1), f.x), f.y);
}

vec2 triangle_uv(uint tri, float u, float v) {
    uvec3 idx = uvec3(indices[3u * tri], indices[3u * tri + 1u], indices[3u * tri + 2u]);
    return (1.0 - u - v) * uvs[idx.x] + u * uvs[idx.y] + v * uvs[idx.z];
}

// Alpha-masked materials are cut out during traversal.
bool bvh_alpha_test(uint tri, float u, float v) {
    GpuMaterialLayout m = materials[tri_materials[tri]];
    if (((m.flags >> MATERIAL_ALPHA_SHIFT) & 3u) != 1u) {
        return true;
    }
    float a = m.base_color.a;
    if (m.base_color_texture != NO_TEXTURE) {
        a *= sample_texture(m.base_color_texture, triangle_uv(tri, u, v)).a;
    }
    return a >= m.alpha_cutoff;
}
#define BVH_ALPHA_TEST
#include "../common/traverse.glsl"

// ---------------------------------------------------------------- surfaces
struct Surface {
    vec3 p;
    vec3 ng;        // geometric normal, facing the incoming ray
    vec3 ns;        // shading normal, same side as ng
    bool front;     // the ray hit the triangle's front (counter-clockwise) face
    vec3 base;
    float metallic;
    float roughness;
    bool diffuse_only;
    vec3 emission;  // emitted radiance towards the ray (zero from a back face of a one-sided material)
};

vec3 vertex_normal(uint i) {
    return vec3(vertex_data[6u * i + 3u], vertex_data[6u * i + 4u], vertex_data[6u * i + 5u]);
}

Surface surface_at(TraceRay r, TraceHit h) {
    Surface s;
    uint tri = h.triangle;
    vec3 p0 = bvh_tris[3u * tri].xyz, p1 = bvh_tris[3u * tri + 1u].xyz, p2 = bvh_tris[3u * tri + 2u].xyz;
    float w0 = 1.0 - h.u - h.v;
    s.p = w0 * p0 + h.u * p1 + h.v * p2;
    vec3 ng = normalize(cross(p1 - p0, p2 - p0));
    uvec3 idx = uvec3(indices[3u * tri], indices[3u * tri + 1u], indices[3u * tri + 2u]);
    vec3 ns = w0 * vertex_normal(idx.x) + h.u * vertex_normal(idx.y) + h.v * vertex_normal(idx.z);
    ns = dot(ns, ns) > 0.0 ? normalize(ns) : ng;
    GpuMaterialLayout m = materials[tri_materials[tri]];
    vec2 uv = vec2(0.0);
    bool textured = m.base_color_texture != NO_TEXTURE || m.metallic_roughness_texture != NO_TEXTURE || m.normal_texture != NO_TEXTURE
        || m.emissive_texture != NO_TEXTURE || m.occlusion_texture != NO_TEXTURE;
    if (textured) {
        uv = triangle_uv(tri, h.u, h.v);
    }
    if (m.normal_texture != NO_TEXTURE) {
        // Tangent frame of the triangle's texture mapping (glTF: v runs down the image, the
        // map's green axis up, hence the minus on the bitangent).
        vec2 t0 = uvs[idx.x], t1 = uvs[idx.y], t2 = uvs[idx.z];
        vec3 e1 = p1 - p0, e2 = p2 - p0;
        vec2 d1 = t1 - t0, d2 = t2 - t0;
        float det = d1.x * d2.y - d1.y * d2.x;
        if (abs(det) > 1e-20) {
            vec3 tangent = (e1 * d2.y - e2 * d1.y) / det;
            vec3 bitangent = (e2 * d1.x - e1 * d2.x) / det;
            tangent = normalize(tangent - ns * dot(ns, tangent));
            bitangent = cross(ns, tangent) * (dot(cross(ns, tangent), bitangent) < 0.0 ? -1.0 : 1.0);
            vec3 mtex = sample_texture(m.normal_texture, uv).xyz * 2.0 - 1.0;
            vec3 mapped = tangent * mtex.x * m.normal_scale - bitangent * mtex.y * m.normal_scale + ns * mtex.z;
            if (dot(mapped, mapped) > 0.0) {
                ns = normalize(mapped);
            }
        }
    }
    s.front = dot(ng, r.direction) < 0.0;
    if (!s.front) {
        ng = -ng;
        ns = -ns;
    }
    // A shading normal on the far side of the surface would light the wrong hemisphere.
    if (dot(ns, ng) <= 0.0) {
        ns = ng;
    }
    s.ng = ng;
    s.ns = ns;
    vec4 base = m.base_color;
    if (m.base_color_texture != NO_TEXTURE) {
        base *= sample_texture(m.base_color_texture, uv);
    }
    s.base = base.rgb;
    s.metallic = m.metallic;
    s.roughness = m.roughness;
    if (m.metallic_roughness_texture != NO_TEXTURE) {
        vec4 mr = sample_texture(m.metallic_roughness_texture, uv);
        s.metallic *= mr.b;
        s.roughness *= mr.g;
    }
    s.metallic = clamp(s.metallic, 0.0, 1.0);
    s.roughness = clamp(s.roughness, 0.0, 1.0);
    s.diffuse_only = (m.flags & MATERIAL_DIFFUSE_ONLY) != 0u;
    vec3 e = m.emission;
    if (m.emissive_texture != NO_TEXTURE && any(greaterThan(e, vec3(0.0)))) {
        e *= sample_texture(m.emissive_texture, uv).rgb;
    }
    bool double_sided = (m.flags & MATERIAL_DOUBLE_SIDED) != 0u;
    s.emission = (s.front || double_sided) ? e : vec3(0.0);
    return s;
}

// ---------------------------------------------------------------- BRDF
float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

float ggx_d(float n_h, float a2) {
    float d = n_h * n_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

float smith_g1(float n_x, float a2) {
    return 2.0 * n_x / (n_x + sqrt(a2 + (1.0 - a2) * n_x * n_x));
}

float alpha_of(Surface s) {
    return max(s.roughness * s.roughness, 1e-3);
}

// f(wo, wi) · |n·wi|, zero below the geometric surface.
vec3 brdf_cos(Surface s, vec3 wo, vec3 wi) {
    if (dot(s.ng, wi) <= 0.0) {
        return vec3(0.0);
    }
    float n_l = dot(s.ns, wi);
    float n_v = dot(s.ns, wo);
    if (n_l <= 0.0 || n_v <= 0.0) {
        return vec3(0.0);
    }
    if (s.diffuse_only) {
        return s.base / PI * n_l;
    }
    vec3 h = normalize(wo + wi);
    float a = alpha_of(s);
    float a2 = a * a;
    float d = ggx_d(max(dot(s.ns, h), 0.0), a2);
    float vis = 0.5 / (n_l * sqrt(n_v * n_v * (1.0 - a2) + a2) + n_v * sqrt(n_l * n_l * (1.0 - a2) + a2));
    vec3 f0 = mix(vec3(0.04), s.base, s.metallic);
    vec3 f = f0 + (1.0 - f0) * pow(1.0 - max(dot(wo, h), 0.0), 5.0);
    return ((1.0 - f) * (1.0 - s.metallic) * s.base / PI + f * d * vis) * n_l;
}

// Probability of choosing the specular lobe.
float specular_probability(Surface s, vec3 wo) {
    if (s.diffuse_only) {
        return 0.0;
    }
    vec3 f0 = mix(vec3(0.04), s.base, s.metallic);
    float fresnel = luminance(f0 + (1.0 - f0) * pow(1.0 - clamp(dot(s.ns, wo), 0.0, 1.0), 5.0));
    float diffuse = luminance(s.base) * (1.0 - s.metallic) * (1.0 - fresnel);
    return clamp(fresnel / max(fresnel + diffuse, 1e-6), 0.05, 0.95);
}

mat3 frame(vec3 n) {
    vec3 t = abs(n.z) < 0.999 ? normalize(cross(vec3(0.0, 0.0, 1.0), n)) : normalize(cross(vec3(1.0, 0.0, 0.0), n));
    return mat3(t, cross(n, t), n);
}

// Solid-angle density of sampling wi with `sample_brdf`.
float brdf_pdf(Surface s, vec3 wo, vec3 wi) {
    float n_l = dot(s.ns, wi);
    if (n_l <= 0.0 || dot(s.ng, wi) <= 0.0) {
        return 0.0;
    }
    float diffuse = n_l / PI;
    float ps = specular_probability(s, wo);
    if (ps == 0.0) {
        return diffuse;
    }
    float n_v = max(dot(s.ns, wo), 1e-6);
    vec3 h = normalize(wo + wi);
    float a = alpha_of(s);
    float a2 = a * a;
    float specular = smith_g1(n_v, a2) * ggx_d(max(dot(s.ns, h), 0.0), a2) / (4.0 * n_v);
    return ps * specular + (1.0 - ps) * diffuse;
}

// GGX visible-normal sampling (Heitz 2018) in the local frame where the normal is +z.
vec3 sample_vndf(vec3 v, float a, vec2 xi) {
    vec3 vh = normalize(vec3(a * v.x, a * v.y, v.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(xi.x);
    float phi = 2.0 * PI * xi.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(a * nh.x, a * nh.y, max(nh.z, 0.0)));
}

vec3 sample_brdf(Surface s, vec3 wo) {
    mat3 f = frame(s.ns);
    float ps = specular_probability(s, wo);
    vec2 xi = vec2(rnd(), rnd());
    if (rnd() < ps) {
        vec3 v = transpose(f) * wo;
        vec3 h = f * sample_vndf(v, alpha_of(s), xi);
        return reflect(-wo, h);
    }
    float r = sqrt(xi.x);
    float phi = 2.0 * PI * xi.y;
    return f * vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - xi.x)));
}

// ---------------------------------------------------------------- emitters
float power_heuristic(float a, float b) {
    float a2 = a * a;
    return a2 / max(a2 + b * b, 1e-30);
}

// Whether something blocks the segment from `from`, on a surface of geometric normal `n` (the
// side the segment leaves by), to `to`. The length is measured from the offset origin: measured
// from `from`, a segment to a point on an emissive triangle reached that triangle (and was
// blocked by it) wherever the offset exceeded the 1e-5 relative margin, e.g. on surfaces facing
// the emitter at coordinates >= 0.5 from the origin. Emitter points are offset off their own
// surface towards `from` by the caller.
bool occluded(vec3 from, vec3 n, vec3 to) {
    vec3 o = offset_ray_origin(from, n);
    vec3 d = to - o;
    float dist = length(d);
    if (!(dist > 0.0)) {
        return false;
    }
    TraceRay r = make_ray(o, d / dist, 0.0, dist * (1.0 - 1e-5));
    return trace(r, true).t != NO_HIT;
}

// Whether something blocks the ray from `from` (as for `occluded`) in direction `dir`, unbounded.
bool occluded_ray(vec3 from, vec3 n, vec3 dir) {
    return trace(make_ray(offset_ray_origin(from, n), dir, 0.0, 3.4e38), true).t != NO_HIT;
}

uint choose_emitter(float xi) {
    uint lo = 0u, hi = rc.size.w - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (emitters[mid].cdf < xi) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Next-event estimation: radiance arriving at s from one emitter, MIS-weighted.
vec3 sample_emitter(Surface s, vec3 wo) {
    if (rc.size.w == 0u) {
        return vec3(0.0);
    }
    GpuEmitter e = emitters[choose_emitter(rnd())];
    vec3 origin = s.p;
    if (e.kind == EMITTER_TRIANGLE) {
        uint tri = e.index;
        vec3 p0 = bvh_tris[3u * tri].xyz, p1 = bvh_tris[3u * tri + 1u].xyz, p2 = bvh_tris[3u * tri + 2u].xyz;
        float su = sqrt(rnd());
        float b1 = 1.0 - su, b2 = rnd() * su;
        vec3 q = (1.0 - b1 - b2) * p0 + b1 * p1 + b2 * p2;
        vec3 c = cross(p1 - p0, p2 - p0);
        float area = 0.5 * length(c);
        vec3 nl = c / max(2.0 * area, 1e-30);
        vec3 to = q - origin;
        float d2 = dot(to, to);
        float d = sqrt(d2);
        vec3 wi = to / d;
        float cos_l = -dot(nl, wi);
        GpuMaterialLayout m = materials[tri_materials[tri]];
        if ((m.flags & MATERIAL_DOUBLE_SIDED) != 0u) {
            cos_l = abs(cos_l);
        }
        if (cos_l <= 0.0 || area <= 0.0) {
            return vec3(0.0);
        }
        vec3 f = brdf_cos(s, wo, wi);
        // The sampled point, moved off the emitter towards the shading point: the shadow ray
        // must not reach the emitter's own surface.
        vec3 q_off = offset_ray_origin(q, dot(nl, wi) < 0.0 ? nl : -nl);
        if (all(equal(f, vec3(0.0))) || occluded(origin, s.ng, q_off)) {
            return vec3(0.0);
        }
        vec3 le = m.emission;
        if (m.emissive_texture != NO_TEXTURE) {
            le *= sample_texture(m.emissive_texture, triangle_uv(tri, b1, b2)).rgb;
        }
        float pdf_light = e.pdf * d2 / (cos_l * area);
        return f * le * power_heuristic(pdf_light, brdf_pdf(s, wo, wi)) / pdf_light;
    }
    GpuLight l = lights[e.index];
    vec3 wi;
    vec3 target;  // the point the shadow ray ends at (directional lights: none)
    float dist;
    vec3 li;
    float pdf_light = e.pdf;
    bool delta = true;
    if (l.kind == LIGHT_DIRECTIONAL) {
        wi = -l.direction;
        target = vec3(0.0);
        dist = 3.4e38;
        li = l.radiance;
    } else if (l.kind == LIGHT_RECT) {
        vec3 up = cross(l.direction, l.right);
        vec3 q = l.position + l.right * (rnd() - 0.5) * l.width + up * (rnd() - 0.5) * l.height;
        target = q;
        vec3 to = q - origin;
        float d2 = dot(to, to);
        dist = sqrt(d2);
        wi = to / dist;
        float cos_l = dot(-wi, l.direction);
        float area = l.width * l.height;
        if (cos_l <= 0.0 || area <= 0.0 || (l.range > 0.0 && dist > l.range)) {
            return vec3(0.0);
        }
        li = l.radiance;
        pdf_light = e.pdf * d2 / (cos_l * area);
        delta = false;
    } else {
        target = l.position;
        vec3 to = l.position - origin;
        float d2 = dot(to, to);
        dist = sqrt(d2);
        wi = to / max(dist, 1e-30);
        if (dist <= 0.0 || (l.range > 0.0 && dist > l.range)) {
            return vec3(0.0);
        }
        float cone = 1.0;
        if (l.kind == LIGHT_SPOT) {
            float t = clamp((dot(-wi, l.direction) - l.cos_outer) / max(l.cos_inner - l.cos_outer, 1e-6), 0.0, 1.0);
            cone = t * t * (3.0 - 2.0 * t);
        }
        li = l.radiance * cone / d2;
    }
    vec3 f = brdf_cos(s, wo, wi);
    if (all(equal(f, vec3(0.0))) || all(equal(li, vec3(0.0)))) {
        return vec3(0.0);
    }
    if (l.kind == LIGHT_DIRECTIONAL ? occluded_ray(origin, s.ng, wi) : occluded(origin, s.ng, target)) {
        return vec3(0.0);
    }
    float weight = delta ? 1.0 : power_heuristic(pdf_light, brdf_pdf(s, wo, wi));
    return f * li * weight / pdf_light;
}

// Rect lights are not geometry: a BRDF-sampled ray sees one when it crosses its rectangle
// from the front before the next surface. Returns the MIS-weighted radiance.
vec3 rect_lights_seen(vec3 origin, vec3 dir, float tmax, float pdf_brdf) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < rc.size.w; i++) {
        GpuEmitter e = emitters[i];
        if (e.kind != EMITTER_LIGHT || lights[e.index].kind != LIGHT_RECT) {
            continue;
        }
        GpuLight l = lights[e.index];
        float denom = dot(dir, l.direction);
        if (denom >= 0.0) {
            continue;
        }
        float t = dot(l.position - origin, l.direction) / denom;
        if (t <= 0.0 || t >= tmax || (l.range > 0.0 && t > l.range)) {
            continue;
        }
        vec3 q = origin + dir * t - l.position;
        vec3 up = cross(l.direction, l.right);
        if (abs(dot(q, l.right)) > 0.5 * l.width || abs(dot(q, up)) > 0.5 * l.height) {
            continue;
        }
        float area = l.width * l.height;
        float pdf_light = e.pdf * t * t / (-denom * area);
        sum += l.radiance * (pdf_brdf > 0.0 ? power_heuristic(pdf_brdf, pdf_light) : 1.0);
    }
    return sum;
}

// ---------------------------------------------------------------- paths
vec3 radiance(TraceRay r) {
    vec3 result = vec3(0.0);
    vec3 throughput = vec3(1.0);
    float pdf_brdf = 0.0;  // density of the last BRDF sample; 0 for camera rays (no MIS)
    vec3 last_p = r.origin;
    for (uint depth = 0u; depth < rc.params.y; depth++) {
        TraceHit h = trace(r, false);
        float tmax = h.t == NO_HIT ? 3.4e38 : h.t;
        result += throughput * rect_lights_seen(r.origin, r.direction, tmax, pdf_brdf);
        if (h.t == NO_HIT) {
            result += throughput * rc.sky.rgb;
            break;
        }
        Surface s = surface_at(r, h);
        if (any(greaterThan(s.emission, vec3(0.0)))) {
            float weight = 1.0;
            int e = tri_emitter[h.triangle];
            if (pdf_brdf > 0.0 && e >= 0) {
                vec3 p0 = bvh_tris[3u * h.triangle].xyz, p1 = bvh_tris[3u * h.triangle + 1u].xyz, p2 = bvh_tris[3u * h.triangle + 2u].xyz;
                float area = 0.5 * length(cross(p1 - p0, p2 - p0));
                float d = h.t * length(r.direction);
                float cos_l = abs(dot(s.ng, normalize(r.direction)));
                float pdf_light = emitters[e].pdf * d * d / max(cos_l * area, 1e-30);
                weight = power_heuristic(pdf_brdf, pdf_light);
            }
            result += throughput * s.emission * weight;
        }
        vec3 wo = -normalize(r.direction);
        result += throughput * sample_emitter(s, wo);
        vec3 wi = sample_brdf(s, wo);
        pdf_brdf = brdf_pdf(s, wo, wi);
        if (pdf_brdf <= 0.0) {
            break;
        }
        throughput *= brdf_cos(s, wo, wi) / pdf_brdf;
        if (depth >= 3u) {
            float q = min(max(throughput.r, max(throughput.g, throughput.b)), 0.95);
            if (rnd() >= q) {
                break;
            }
            throughput /= q;
        }
        if (all(equal(throughput, vec3(0.0)))) {
            break;
        }
        r = make_ray(offset_ray_origin(s.p, s.ng), wi, 0.0, 3.4e38);
    }
    return result;
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(pixel, rc.size.xy))) {
        return;
    }
    rng = hash(pixel.x + rc.size.x * pixel.y) ^ hash(sample_index * 0x9e3779b9u + rc.params.z);
    vec2 jitter = vec2(rnd(), rnd());
    vec2 ndc = vec2((float(pixel.x) + jitter.x) / float(rc.size.x) * 2.0 - 1.0, 1.0 - (float(pixel.y) + jitter.y) / float(rc.size.y) * 2.0);
    vec3 dir = normalize(rc.forward.xyz + rc.right.xyz * ndc.x * rc.eye.w * rc.right.w + rc.up.xyz * ndc.y * rc.eye.w);
    vec3 l = radiance(make_ray(rc.eye.xyz, dir, 0.0, 3.4e38));
    // A non-finite sample would poison the average; it is dropped (counted as zero).
    if (any(isnan(l)) || any(isinf(l))) {
        l = vec3(0.0);
    }
    vec3 sum = sample_index == 0u ? l : imageLoad(accumulation, ivec2(pixel)).rgb + l;
    imageStore(accumulation, ivec2(pixel), vec4(sum, 1.0));
}
