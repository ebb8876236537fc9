// Diffuse global illumination by path tracing from the G-buffer: the estimator, independent of
// the ray structure that answers its rays.
//
// Per pixel and frame, one cosine-weighted direction around the primary surface's shading normal
// (below its geometric surface: zero) and the radiance L arriving along it: a one-sample
// estimate of the mean incoming radiance over the cosine-weighted hemisphere, irradiance / π,
// which the composition multiplies by the diffuse weight (Lambert: the base colour) in place of
// the sky's diffuse ambient. Averaged over frames while the camera is still.
//
// What counts, so that the frame counts every light path exactly once: the direct pass covers
// the analytic lights (point, spot, directional, rect) at the primary surface, and this pass
// replaces its diffuse sky ambient. So along the first ray:
//  - the sky on a miss counts (it is no longer in the direct pass; the sky is no emitter of the
//    table, no next-event estimation reaches it);
//  - an emissive triangle of the emitter table it hits counts with weight 1 when the frame has
//    no direct light of emissive surfaces (`--direct none`): BRDF (cosine) sampling is then the
//    only strategy for them at the primary surface and there is nothing to weigh it against;
//    with it (FRAME_RT_DIRECT) weight 0: the direct-light image integrates every emitter of the
//    table at the primary surface, whatever strategy (RIS, reuse) chose its samples;
//  - a rect light it crosses does not count: the direct pass integrates rect lights.
// At each hit, next-event estimation towards one emitter of the table (analytic lights and
// emissive triangles, the path tracer's `sample_emitter`). At the last hit (`rt.gi_bounces`
// scattering events after the primary surface) it is unweighted: no continuation follows that
// could reach the emitters; the sky, which is no emitter of the table, comes from one
// BRDF-sampled shadow ray that escapes (`sky_seen`). Before the last hit next-event estimation
// is weighted with the power heuristic and the path continues with a BRDF sample, whose ray
// counts the emissive triangles it hits and the rect lights it crosses with the complementary
// weights (as the path tracer does) and the sky on a miss. Delta lights count by next-event
// estimation alone. No Russian roulette (at most 8 bounces).
//
// The includer includes hybrid.glsl (the descriptor set: emitter table, `rt_gi`) and defines
// before including this file the ray structure's answers:
//   bool gi_hit(TraceRay r, vec3 origin_ng, bool exact, out Surface s)
//       the closest surface along r (r.origin already offset off the surface of geometric normal
//       `origin_ng` it leaves, r.direction unit length): true and the surface, or false on a
//       miss. `exact` is true for continuations sampled from a specular lobe, where an
//       approximate answer would show; false for diffuse ones.
//   bool gi_occluded(vec3 from, vec3 ng, vec3 to)
//       whether the segment from `from` (on a surface of geometric normal `ng`, not offset) to
//       `to` is blocked: next-event shadow rays towards points on emitters.
//   bool gi_occluded_dir(vec3 from, vec3 ng, vec3 dir)
//       the same for the unbounded ray along `dir` (directional lights).
// Defining GI_HIT_RADIANCE and
//   bool gi_hit_radiance(TraceRay r, vec3 origin_ng, out vec3 radiance)
// instead ends every path at its first hit with the radiance the structure stores for it.
// `gi_main()` is the kernel's body.
#ifndef KILN_GI_GLSL
#define KILN_GI_GLSL

uint emitter_count() {
    return rt.emitters;
}

bool emitter_occluded(vec3 from, vec3 ng, vec3 to) {
    return gi_occluded(from, ng, to);
}

bool emitter_occluded_dir(vec3 from, vec3 ng, vec3 dir) {
    return gi_occluded_dir(from, ng, dir);
}

#include "../common/emitters.glsl"

// The sky reflected at the last hit s towards wo: no emitter of the table, so one BRDF-sampled
// shadow ray that escapes brings it (rect lights it crosses do not count: the unweighted
// next-event estimation has them).
vec3 sky_seen(Surface s, vec3 wo) {
    if (env_present()) {
        // An environment has a sampling table: next-event estimation alone (unweighted).
        return sample_environment(s, wo, frame.sky.rgb, false);
    }
    if (all(equal(frame.sky.rgb, vec3(0.0)))) {
        return vec3(0.0);
    }
    vec3 wi = sample_brdf(s, wo);
    float pdf = brdf_pdf(s, wo, wi);
    if (pdf <= 0.0 || gi_occluded_dir(s.p, facing(s.ng, wi), wi)) {
        return vec3(0.0);
    }
    return brdf_cos(s, wo, wi) / pdf * frame.sky.rgb;
}

// One sample of the radiance arriving at the primary surface s along a cosine-weighted
// direction (the mean over samples is irradiance / π).
vec3 gi_sample(Primary s) {
    float r2 = rnd();
    float phi = 2.0 * PI * rnd();
    float r1 = sqrt(r2);
    vec3 dir = basis(s.n) * vec3(r1 * cos(phi), r1 * sin(phi), sqrt(max(0.0, 1.0 - r2)));
    if (dot(dir, s.ng) <= 0.0) {
        return vec3(0.0);
    }
    TraceRay r = make_ray(offset_ray_origin(s.p, s.ng), dir, 0.0, 3.4e38);
    vec3 origin_ng = s.ng;
#ifdef GI_HIT_RADIANCE
    // The structure stores the light leaving every hit (the pre-illuminated line space): one
    // lookup ends the path, the sky on a miss.
    vec3 stored;
    return gi_hit_radiance(r, origin_ng, stored) ? stored : env_radiance(dir, frame.sky.rgb);
#endif
    bool exact = false;
    vec3 result = vec3(0.0);
    vec3 throughput = vec3(1.0);
    float pdf_brdf = 0.0;  // density of the BRDF sample that made r; 0 for the first ray
    for (uint bounce = 1u;; bounce++) {
        Surface h;
        bool hit = gi_hit(r, origin_ng, exact, h);
        // Path regularisation (Kaplanyan & Dachsbacher 2013): the hit's glossy lobe at least
        // `--gi-regularize` rough. The path left the primary surface along a cosine lobe; a
        // sharp highlight of a light at its hit is one rare, very bright sample (pica_pica's
        // relMSE after 64 frames of rt-4 0.0185, 0.0070 at 0.5, FLIP better at 1 and 4 frames
        // and equal at 64; at 1.0 the lost gloss costs more than the noise it saves).
        h.mat.roughness = max(h.mat.roughness, rt.gi_min_roughness);
        h.mat.clearcoat_roughness = max(h.mat.clearcoat_roughness, rt.gi_min_roughness);
        if (bounce > 1u) {
            float tmax = hit ? length(h.p - r.origin) : 3.4e38;
            result += throughput * rect_lights_seen(r.origin, r.direction, tmax, pdf_brdf);
        }
        if (!hit) {
            // After the first bounce the environment was also sampled at the last hit.
            float w = bounce > 1u ? environment_seen_weight(r.direction, pdf_brdf) : 1.0;
            result += throughput * env_radiance(r.direction, frame.sky.rgb) * w;
            break;
        }
        bool direct_counts = bounce == 1u && (frame.size.w & FRAME_RT_DIRECT) != 0u && tri_emitter[h.triangle] >= 0;
        if (any(greaterThan(h.emission, vec3(0.0))) && !direct_counts) {
            float d = length(h.p - r.origin);
            float cos_l = abs(dot(h.ng, r.direction));
            result += throughput * h.emission * triangle_emission_weight(h.triangle, d, cos_l, pdf_brdf);
        }
        vec3 wo = -r.direction;
        bool last = bounce >= rt.gi_bounces;
        result += throughput * sample_emitter(h, wo, !last);
        if (last) {
            result += throughput * sky_seen(h, wo);
            break;
        }
        result += throughput * sample_environment(h, wo, frame.sky.rgb, true);
        vec3 wi = sample_brdf_lobe(h, wo, exact);
        pdf_brdf = brdf_pdf(h, wo, wi);
        if (pdf_brdf <= 0.0) {
            break;
        }
        throughput *= brdf_cos(h, wo, wi) / pdf_brdf;
        if (all(equal(throughput, vec3(0.0)))) {
            break;
        }
        origin_ng = facing(h.ng, wi);
        r = make_ray(offset_ray_origin(h.p, origin_ng), wi, 0.0, 3.4e38);
    }
    return result;
}

void gi_main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    Primary s;
    vec3 l = vec3(0.0);
    if (primary_at(pixel, s)) {
        seed_rng(pixel, 5u);
        l = gi_sample(s);
        // A non-finite sample would poison the average; it is dropped (counted as zero).
        if (any(isnan(l)) || any(isinf(l))) {
            l = vec3(0.0);
        }
    }
    // Alpha: the square of the sample's luminance, whose running mean is the second moment the
    // denoiser estimates the noise from (shaders/denoise/).
    imageStore(rt_gi, pixel, accumulate(imageLoad(rt_gi, pixel), vec4(l, min(luminance(l) * luminance(l), 3.0e38))));
}

#endif
