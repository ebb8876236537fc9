#version 460
#extension GL_EXT_control_flow_attributes : require
// The reference path tracer: unbiased samples per pixel, `sample_count` per dispatch, accumulated.
//
// Paths: camera rays jittered over the pixel (box filter); at each vertex next-event estimation
// towards one emitter chosen in proportion to its power (analytic lights, emissive triangles),
// and a BRDF-sampled continuation; emitters the continuation hits (emissive triangles, rect
// lights) count with the power heuristic against the emitter sampling, delta lights by NEE
// alone; with an environment, the vertex's one shadow ray goes either to the emitter or towards
// a direction drawn from the environment's table, chosen with probability `rc.sky.w` by their
// power (player/src/scene/reference.rs, `environment_share`), each weighed with the power
// heuristic (its density times its choice's probability) against the BRDF-sampled ray. (Two
// shadow rays per vertex, one to each, held Khronos ToyCar, lit by a studio environment and a
// few dim decals, at 73 M samples/s on an H200; one, at 86 M with the same error per sample.)
// Russian roulette from the fourth vertex; `params.y` caps the length as a safety net.
// `params.w` > 0 limits the bounces: the light arriving after that many scattering events
// counts and nothing further (1: direct light alone), what a benchmark compares a frame without
// indirect light against.
// BRDF: glTF metallic-roughness (Lambert diffuse weighted by 1 − F, GGX with height-correlated
// Smith and Schlick F; α = roughness²) sampled with cosine-weighted diffuse and GGX visible
// normals (Heitz 2018), or pure Lambert for diffuse-only materials. All surfaces are two-sided
// for reflection; emission leaves the front face only unless the material is double-sided.
// Textures: mip 0, bilinear, from a texel buffer (portable: no descriptor indexing needed); the
// materials' by one texel chosen by its bilinear weight (the same mean, a quarter of the decoding).
// Participating media (`rc.media.x` homogeneous boxes; overlapping boxes add their
// coefficients): free-flight distances sampled in one colour channel chosen uniformly and
// weighted by the mean of the three channels' densities (spectral MIS, so chromatic media stay
// unbiased), between the ray's boundary crossings of the boxes; at a scattering point, next-
// event estimation with the Henyey–Greenstein phase function (the scattering-weighted mix
// where boxes overlap) and a phase-sampled continuation, which the power heuristic weighs
// against each other as at surfaces (the environment, sampled at surfaces only, counts at full
// weight where a phase-sampled ray escapes); shadow rays carry the analytic transmittance of every
// box they cross. Scattering in a medium counts as a bounce.
#include "../common/layout.glsl"
#include "../common/packing.glsl"

// Samples per pixel taken side by side: the workgroup's z (specialization constant 2, `STREAMS`
// in passes/pathtrace.rs), each invocation of a pixel every STREAMS-th sample of the
// dispatch, their sums joined in shared memory. A small image has too few pixels to fill a large
// GPU (640 × 360 is 230,400 invocations; an H200 keeps 270,336 in flight), and a workgroup's
// slowest path holds up fewer of its pixels' samples.
layout(local_size_x = 8, local_size_y = 8, local_size_z_id = 2) in;
const uint MAX_STREAMS = 4u;
shared vec3 stream_sums[64u * MAX_STREAMS];

layout(set = 0, binding = 0) uniform Constants { ReferenceConstants rc; };
#include "../common/scene_bindings.glsl"   // bindings 1-8: the scene, the lights
#include "../common/lights.glsl"
layout(set = 0, binding = 9, std430) readonly buffer Emitters { GpuEmitter emitters[]; };
layout(set = 0, binding = 10, std430) readonly buffer TriEmitters { int tri_emitter[]; };
layout(set = 0, binding = 11, std430) readonly buffer Texels { uint texels[]; };
layout(set = 0, binding = 12, std430) readonly buffer Textures { GpuTexture textures[]; };
layout(set = 0, binding = 13, rgba32f) uniform image2D accumulation;
layout(set = 0, binding = 14, std430) readonly buffer Media { GpuMedium media[]; };
#define ENV_BINDING 15
#include "../common/environment.glsl"   // bindings 15-16
// The dispatch's samples: `sample_count` of them from index `sample_index` (0 first: the
// dispatch starting at 0 overwrites the accumulation, later ones add to it).
layout(push_constant) uniform Samples {
    uint sample_index;
    uint sample_count;
};

#include "../common/random.glsl"
// The materials' textures are filtered stochastically (`common/textures.glsl`): one texel of
// mip 0's bilinear footprint per lookup, chosen by its weight.
#define TEXTURE_STOCHASTIC
float texture_xi() {
    return rnd();
}
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

#define EMITTER_TRANSMITTANCE
#define EMITTER_CHOICES
#include "../common/emitters.glsl"

// ---------------------------------------------------------------- media
const float FAR = 3.4e38;

// Whether the file has participating media (set by the player, `passes/pathtrace.rs`): without,
// the compiler drops the media's code, whose registers every path would otherwise reserve.
layout(constant_id = 1) const bool HAS_MEDIA = true;

uint medium_count() {
    return HAS_MEDIA ? rc.media.x : 0u;
}

#include "../common/media.glsl"

// The ray of the current path segment, for the weight of the rect lights it crosses.
vec3 segment_origin;
vec3 segment_dir;

// Transmittance from the origin towards an emitter sample (to its point, or out of every box).
vec3 emitter_transmittance(vec3 from, EmitterSample es) {
    if (medium_count() == 0u) {
        return vec3(1.0);
    }
    float dist = es.directional ? FAR : length(es.target - from);
    return exp(-optical_depth(medium_count(), from, es.wi, 0.0, dist));
}

// A rect light crossed at distance t of the current segment counts when the sampled flight got
// past it: weighted by the transmittance over the probability of getting that far.
vec3 emitter_seen_weight(float t) {
    if (medium_count() == 0u) {
        return vec3(1.0);
    }
    vec3 tr = exp(-optical_depth(medium_count(), segment_origin, segment_dir, 0.0, t));
    return tr / max(dot(tr, vec3(1.0 / 3.0)), 1e-30);
}

// The scattering at a point in the media: the boxes holding it, by their scattering.
struct MediumPoint {
    vec3 sigma_s;  // summed over the boxes holding the point
};

bool inside(uint i, vec3 p) {
    return all(greaterThanEqual(p, media[i].min.xyz)) && all(lessThanEqual(p, media[i].max.xyz));
}

vec3 scattering_at(vec3 p) {
    vec3 s = vec3(0.0);
    for (uint i = 0u; i < medium_count(); i++) {
        if (inside(i, p)) {
            s += media[i].sigma_s.rgb;
        }
    }
    return s;
}

// The phase function at p for light travelling along `d_in` leaving along `wi`, per channel
// (the σs-weighted mix of the boxes' HG lobes), and the density its sampling has (the mix
// weighted by each box's mean σs).
vec3 phase(vec3 p, vec3 d_in, vec3 wi, out float pdf) {
    float c = dot(d_in, wi);
    vec3 f = vec3(0.0), total = vec3(0.0);
    float wsum = 0.0;
    pdf = 0.0;
    for (uint i = 0u; i < medium_count(); i++) {
        if (!inside(i, p)) {
            continue;
        }
        vec3 ss = media[i].sigma_s.rgb;
        float v = hg(media[i].min.w, c);
        f += ss * v;
        total += ss;
        float w = dot(ss, vec3(1.0 / 3.0));
        pdf += w * v;
        wsum += w;
    }
    pdf = wsum > 0.0 ? pdf / wsum : 0.0;
    return mix(vec3(0.0), f / max(total, vec3(1e-30)), greaterThan(total, vec3(0.0)));
}

// A direction from the phase mix at p (one box chosen by its mean σs, its HG lobe sampled).
vec3 sample_phase(vec3 p, vec3 d_in) {
    float wsum = 0.0;
    for (uint i = 0u; i < medium_count(); i++) {
        if (inside(i, p)) {
            wsum += dot(media[i].sigma_s.rgb, vec3(1.0 / 3.0));
        }
    }
    float pick = rnd() * wsum;
    float g = 0.0;
    for (uint i = 0u; i < medium_count(); i++) {
        if (inside(i, p)) {
            g = media[i].min.w;
            pick -= dot(media[i].sigma_s.rgb, vec3(1.0 / 3.0));
            if (pick < 0.0) {
                break;
            }
        }
    }
    float u = rnd(), v = rnd();
    float cos_theta;
    if (abs(g) < 1e-3) {
        cos_theta = 1.0 - 2.0 * u;
    } else {
        float q = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
        cos_theta = (1.0 + g * g - q * q) / (2.0 * g);
    }
    cos_theta = clamp(cos_theta, -1.0, 1.0);
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    float phi = 2.0 * PI * v;
    vec3 t = abs(d_in.x) > 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 b1 = normalize(cross(d_in, t));
    vec3 b2 = cross(d_in, b1);
    return normalize(cos_theta * d_in + sin_theta * (cos(phi) * b1 + sin(phi) * b2));
}

// Samples where the unit ray (o, d) first interacts with the media before `tmax`: true with
// the distance `t` and `weight` = transmittance · σs / density for a scattering event (absorption
// is in the weight, not an event), false with `weight` = transmittance / probability of getting
// through when the flight reaches `tmax`.
bool sample_flight(vec3 o, vec3 d, float tmax, out float t, out vec3 weight) {
    int c = min(int(rnd() * 3.0), 2);
    float target = -log(max(1.0 - rnd(), 1e-30));
    vec3 tau = vec3(0.0);
    t = 0.0;
    // Each step crosses one boundary: at most two per box.
    for (uint step = 0u; step <= 2u * medium_count(); step++) {
        float next = tmax;
        vec3 st = vec3(0.0), ss = vec3(0.0);
        for (uint i = 0u; i < medium_count(); i++) {
            vec2 span = box_span(media[i].min.xyz, media[i].max.xyz, o, d, 0.0, tmax);
            if (!(span.y > span.x)) {
                continue;
            }
            if (span.x <= t && span.y > t) {
                next = min(next, span.y);
                st += medium_sigma_t(i);
                ss += media[i].sigma_s.rgb;
            } else if (span.x > t) {
                next = min(next, span.x);
            }
        }
        float need = target - tau[c];
        if (st[c] > 0.0 && need <= st[c] * (next - t)) {
            float ts = t + need / st[c];
            tau += st * (ts - t);
            t = ts;
            vec3 tr = exp(-tau);
            float density = dot(st * tr, vec3(1.0 / 3.0));
            weight = density > 0.0 ? tr * ss / density : vec3(0.0);
            return true;
        }
        tau += st * (next - t);
        t = next;
        if (t >= tmax) {
            break;
        }
    }
    t = tmax;
    vec3 tr = exp(-tau);
    float through = dot(tr, vec3(1.0 / 3.0));
    weight = through > 0.0 ? tr / through : vec3(0.0);
    return false;
}

// Next-event estimation from a point in the media.
vec3 medium_emitter(vec3 p, vec3 d_in) {
    EmitterSample es = sample_emitter_light(p);
    if (!es.valid) {
        return vec3(0.0);
    }
    float pdf_phase;
    vec3 f = phase(p, d_in, es.wi, pdf_phase);
    if (all(equal(f, vec3(0.0))) || emitter_blocked(es, p, vec3(0.0))) {
        return vec3(0.0);
    }
    float weight = es.delta ? 1.0 : power_heuristic(es.pdf, pdf_phase);
    return f * es.li * weight * emitter_transmittance(p, es) / es.pdf;
}

// ---------------------------------------------------------------- paths
// A path being sampled: the ray of its next segment and what it has gathered.
struct Path {
    TraceRay r;
    vec3 result;
    vec3 throughput;
    float pdf_brdf;  // density of the last BRDF sample; 0 for camera rays (no MIS)
    float pdf_env;   // pdf_brdf where the last vertex also sampled the environment, else 0
    float choice_emitter;  // the last vertex's probabilities of sampling the emitter table
    float choice_env;      // and the environment (`emitter_choice`, `env_choice`)
    uint depth;
};

// Sample `index` of `pixel`: its random sequence and its camera ray, jittered over the pixel.
Path start_path(uvec2 pixel, uint index) {
    rng = hash(pixel.x + rc.size.x * pixel.y) ^ hash(index * 0x9e3779b9u + rc.params.z);
    vec2 jitter = vec2(rnd(), rnd());
    vec2 ndc = vec2((float(pixel.x) + jitter.x) / float(rc.size.x) * 2.0 - 1.0, 1.0 - (float(pixel.y) + jitter.y) / float(rc.size.y) * 2.0);
    // Perspective (up.w = 0): eye.w is tan(vfov / 2), right.w the aspect ratio. Orthographic
    // (up.w = 1): eye.w is the half-height of the view rectangle around the eye.
    vec3 offset = (rc.right.xyz * ndc.x * rc.right.w + rc.up.xyz * ndc.y) * rc.eye.w;
    bool ortho = rc.up.w != 0.0;
    vec3 dir = ortho ? rc.forward.xyz : normalize(rc.forward.xyz + offset);
    Path path;
    path.r = make_ray(ortho ? rc.eye.xyz + offset : rc.eye.xyz, dir, 0.0, 3.4e38);
    path.result = vec3(0.0);
    path.throughput = vec3(1.0);
    path.pdf_brdf = 0.0;
    path.pdf_env = 0.0;
    path.choice_emitter = 1.0;
    path.choice_env = 1.0;
    path.depth = 0u;
    return path;
}

// Russian roulette from the fourth vertex: false where the path ends.
bool survives(inout Path path) {
    if (path.depth >= 3u) {
        float q = min(max(path.throughput.r, max(path.throughput.g, path.throughput.b)), 0.95);
        if (rnd() >= q) {
            return false;
        }
        path.throughput /= q;
    }
    return !all(equal(path.throughput, vec3(0.0)));
}

// One vertex of the path: traces its segment, gathers the light found there and sets up the
// next segment. False once the path has ended.
bool extend(inout Path path) {
    if (path.depth >= rc.params.y) {
        return false;
    }
    TraceRay r = path.r;
    TraceHit h = trace(r, false);
    float tmax = h.t == NO_HIT ? FAR : h.t;
    segment_origin = r.origin;
    segment_dir = r.direction;
    float t_flight = tmax;
    vec3 flight = vec3(1.0);
    bool scattered = medium_count() != 0u && sample_flight(r.origin, r.direction, tmax, t_flight, flight);
    // What the segment reaches is weighed against the strategies of the vertex it left.
    emitter_choice = path.choice_emitter;
    env_choice = path.choice_env;
    path.result += path.throughput * rect_lights_seen(r.origin, r.direction, t_flight, path.pdf_brdf);
    path.throughput *= flight;
    bool last = rc.params.w != 0u && path.depth >= rc.params.w;
    if (scattered) {
        if (last) {
            return false;
        }
        vec3 p = r.origin + t_flight * r.direction;
        // In a medium the table alone is sampled (the environment counts at full weight).
        emitter_choice = 1.0;
        path.choice_emitter = 1.0;
        path.result += path.throughput * medium_emitter(p, r.direction);
        vec3 wi = sample_phase(p, r.direction);
        vec3 f = phase(p, r.direction, wi, path.pdf_brdf);
        path.pdf_env = 0.0;
        if (path.pdf_brdf <= 0.0) {
            return false;
        }
        path.throughput *= f / path.pdf_brdf;
        if (!survives(path)) {
            return false;
        }
        path.r = make_ray(p, wi, 0.0, FAR);
        path.depth++;
        return true;
    }
    if (h.t == NO_HIT) {
        vec3 d = normalize(r.direction);
        path.result += path.throughput * env_radiance(d, rc.sky.rgb) * environment_seen_weight(d, path.pdf_env);
        return false;
    }
    Surface s = surface_at(r, h);
    if (any(greaterThan(s.emission, vec3(0.0)))) {
        float d = h.t * length(r.direction);
        float cos_l = abs(dot(s.ng, normalize(r.direction)));
        path.result += path.throughput * s.emission * triangle_emission_weight(h.triangle, d, cos_l, path.pdf_brdf);
    }
    if (last) {
        return false;
    }
    vec3 wo = -normalize(r.direction);
    // One shadow ray: towards the environment with probability rc.sky.w, else to an emitter.
    path.choice_env = rc.sky.w;
    path.choice_emitter = 1.0 - rc.sky.w;
    emitter_choice = path.choice_emitter;
    env_choice = path.choice_env;
    if (rnd() < path.choice_env) {
        path.result += path.throughput * sample_environment(s, wo, rc.sky.rgb, true);
    } else {
        path.result += path.throughput * sample_emitter(s, wo, true);
    }
    vec3 wi = sample_brdf(s, wo);
    path.pdf_brdf = brdf_pdf(s, wo, wi);
    path.pdf_env = path.pdf_brdf;
    if (path.pdf_brdf <= 0.0) {
        return false;
    }
    path.throughput *= brdf_cos(s, wo, wi) / path.pdf_brdf;
    if (!survives(path)) {
        return false;
    }
    path.r = make_ray(offset_ray_origin(s.p, facing(s.ng, wi)), wi, 0.0, FAR);
    path.depth++;
    return true;
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    uint stream = gl_LocalInvocationID.z;
    uint streams = min(gl_WorkGroupSize.z, MAX_STREAMS);
    bool inside = all(lessThan(pixel, rc.size.xy));
    // The dispatch's samples as one loop of vertices (path regeneration): an invocation whose
    // path has ended starts its pixel's next sample at once, where a loop over samples would
    // leave it idle until the longest path of its subgroup ended. Paths' lengths vary most
    // where glass and metal keep their throughput (ToyCar); the idle share shrinks as the
    // dispatch's samples grow.
    vec3 sum = vec3(0.0);
    uint taken = stream;
    if (inside && taken < sample_count) {
        Path path = start_path(pixel, sample_index + taken);
        while (taken < sample_count) {
            if (!extend(path)) {
                // A non-finite sample would poison the average; it is dropped (counted as zero).
                if (!any(isnan(path.result)) && !any(isinf(path.result))) {
                    sum += path.result;
                }
                taken += streams;
                if (taken < sample_count) {
                    path = start_path(pixel, sample_index + taken);
                }
            }
        }
    }
    if (streams > 1u) {
        stream_sums[gl_LocalInvocationIndex] = sum;
        barrier();
        if (stream != 0u) {
            return;
        }
        for (uint k = 1u; k < streams; k++) {
            sum += stream_sums[gl_LocalInvocationIndex + 64u * k];
        }
    }
    if (!inside) {
        return;
    }
    if (sample_index != 0u) {
        sum += imageLoad(accumulation, ivec2(pixel)).rgb;
    }
    imageStore(accumulation, ivec2(pixel), vec4(sum, 1.0));
}
