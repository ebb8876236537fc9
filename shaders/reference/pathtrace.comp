#version 460
#extension GL_EXT_control_flow_attributes : require
// The reference path tracer: one unbiased sample per pixel per dispatch, accumulated.
//
// Paths: camera rays jittered over the pixel (box filter); at each vertex next-event estimation
// towards one emitter chosen in proportion to its power (analytic lights, emissive triangles),
// and a BRDF-sampled continuation; emitters the continuation hits (emissive triangles, rect
// lights) count with the power heuristic against the emitter sampling, delta lights by NEE
// alone. Russian roulette from the fourth vertex; `params.y` caps the length as a safety net.
// `params.w` > 0 limits the bounces: the light arriving after that many scattering events
// counts and nothing further (1: direct light alone), what a benchmark compares a frame without
// indirect light against.
// BRDF: glTF metallic-roughness (Lambert diffuse weighted by 1 − F, GGX with height-correlated
// Smith and Schlick F; α = roughness²) sampled with cosine-weighted diffuse and GGX visible
// normals (Heitz 2018), or pure Lambert for diffuse-only materials. All surfaces are two-sided
// for reflection; emission leaves the front face only unless the material is double-sided.
// Textures: mip 0, bilinear, from a texel buffer (portable: no descriptor indexing needed).
#include "../common/layout.glsl"
#include "../common/packing.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Constants { ReferenceConstants rc; };
#include "../common/scene_bindings.glsl"   // bindings 1-8: the scene, the lights
#include "../common/lights.glsl"
layout(set = 0, binding = 9, std430) readonly buffer Emitters { GpuEmitter emitters[]; };
layout(set = 0, binding = 10, std430) readonly buffer TriEmitters { int tri_emitter[]; };
layout(set = 0, binding = 11, std430) readonly buffer Texels { uint texels[]; };
layout(set = 0, binding = 12, std430) readonly buffer Textures { GpuTexture textures[]; };
layout(set = 0, binding = 13, rgba32f) uniform image2D accumulation;
// Index of this sample (0 first): 0 overwrites the accumulation, later ones add to it.
layout(push_constant) uniform Sample { uint sample_index; };

#include "../common/random.glsl"
#include "../common/scene.glsl"

// ---------------------------------------------------------------- emitters
float power_heuristic(float a, float b) {
    float a2 = a * a;
    return a2 / max(a2 + b * b, 1e-30);
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
            cone = spot_cone(l, wi);
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
        float t = rect_light_hit(l, origin, dir, tmax);
        if (t < 0.0) {
            continue;
        }
        float denom = dot(dir, l.direction);
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
        if (rc.params.w != 0u && depth >= rc.params.w) {
            break;
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
