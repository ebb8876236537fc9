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
uint emitter_count() {
    return rc.size.w;
}

bool emitter_occluded(vec3 from, vec3 ng, vec3 to) {
    return occluded(from, ng, to);
}

bool emitter_occluded_dir(vec3 from, vec3 ng, vec3 dir) {
    return occluded_ray(from, ng, dir);
}

#include "../common/emitters.glsl"

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
            float d = h.t * length(r.direction);
            float cos_l = abs(dot(s.ng, normalize(r.direction)));
            result += throughput * s.emission * triangle_emission_weight(h.triangle, d, cos_l, pdf_brdf);
        }
        if (rc.params.w != 0u && depth >= rc.params.w) {
            break;
        }
        vec3 wo = -normalize(r.direction);
        result += throughput * sample_emitter(s, wo, true);
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
    // Perspective (up.w = 0): eye.w is tan(vfov / 2), right.w the aspect ratio. Orthographic
    // (up.w = 1): eye.w is the half-height of the view rectangle around the eye.
    vec3 offset = (rc.right.xyz * ndc.x * rc.right.w + rc.up.xyz * ndc.y) * rc.eye.w;
    bool ortho = rc.up.w != 0.0;
    vec3 dir = ortho ? rc.forward.xyz : normalize(rc.forward.xyz + offset);
    vec3 l = radiance(make_ray(ortho ? rc.eye.xyz + offset : rc.eye.xyz, dir, 0.0, 3.4e38));
    // A non-finite sample would poison the average; it is dropped (counted as zero).
    if (any(isnan(l)) || any(isinf(l))) {
        l = vec3(0.0);
    }
    vec3 sum = sample_index == 0u ? l : imageLoad(accumulation, ivec2(pixel)).rgb + l;
    imageStore(accumulation, ivec2(pixel), vec4(sum, 1.0));
}
