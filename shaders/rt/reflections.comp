#version 460
// Ray-traced glossy reflections (seed 001 §1.5) at full resolution or one ray per 2 × 2 pixels.
// Per traced pixel one GGX visible-normal sample (Heitz 2018) of the specular lobe; the stored
// value is F(v·h) · G2 / G1(v) · L(wi), the unbiased one-sample estimate of the lobe's reflected
// radiance (the composition adds it in place of the split-sum ambient specular). At the hit:
// emission, every light with one hard shadow ray to its centre (as in the thesis), and the sky
// or the probes as unshadowed ambient; a miss sees the sky. A hit on smooth metal traces its own
// lobe once more and shades that second hit the same way (`traced_onwards`).
//
// The shadow rays at the hits are not traced here: this pass stores each light's unshadowed
// term and the hit's ray origin (and a second hit's), and `reflection_shadows.comp`, a small
// kernel, traces them and accumulates. Traced inside this large kernel (low occupancy) they
// took 72 % of its time on an H200; traversal is latency-bound and wants many rays in flight.
//
// Fixes of the thesis's code: surfaces that are too *rough* are skipped (its test was inverted
// and skipped the smooth ones), a sample below the surface contributes zero instead of being
// re-rolled in an unbounded loop (re-rolling biases the estimate), the weight includes the
// masking term and the pdf (it used Fresnel alone), and diffuse-only materials are not traced.
#include "hybrid.glsl"

// One GGX visible-normal sample (Heitz 2018) of the specular lobe of material m at a surface of
// shading normal n and geometric normal ng (both on v's side) seen from v: the reflected
// direction wi and the one-sample weight F(v·h) · G2 / G1(v) of the lobe's reflected radiance
// (the lobe's pdf cancels D and G1); zero below either normal.
vec3 sample_lobe(Material m, vec3 n, vec3 ng, vec3 v, out vec3 wi) {
    float a = ggx_alpha(m.roughness);
    mat3 f = basis(n);
    vec3 h = f * sample_vndf(transpose(f) * v, a, vec2(rnd(), rnd()));
    wi = reflect(-v, h);
    float n_l = dot(n, wi);
    if (n_l <= 0.0 || dot(wi, ng) <= 0.0) {
        return vec3(0.0);
    }
    float a2 = a * a;
    float lv = smith_lambda(max(dot(n, v), 1e-4), a2);
    float g = (1.0 + lv) / (1.0 + lv + smith_lambda(n_l, a2));
    return fresnel_schlick(fresnel_f0(m), fresnel_f90(m), clamp(dot(v, h), 0.0, 1.0)) * g;
}

// The unshadowed term of light l at surface s seen from wo, and the direction towards it.
vec3 light_term(GpuLight l, Surface s, vec3 wo, out vec3 wi) {
    vec3 li = vec3(0.0);
    if (l.kind == LIGHT_DIRECTIONAL) {
        wi = -l.direction;
        li = l.radiance;
    } else {
        vec3 to = l.position - s.p;
        float dist = length(to);
        wi = to / max(dist, 1e-30);
        if (dist > 0.0 && (l.range <= 0.0 || dist <= l.range)) {
            li = l.radiance / (dist * dist);
            if (l.kind == LIGHT_SPOT) {
                li *= spot_cone(l, wi);
            } else if (l.kind == LIGHT_RECT) {
                // The rectangle seen from the hit as one point at its centre.
                li *= max(dot(-wi, l.direction), 0.0) * l.width * l.height;
            }
        }
    }
    return any(greaterThan(li, vec3(0.0))) ? brdf_cos(s, wo, wi) * li : vec3(0.0);
}

bool light_occluded(GpuLight l, vec3 origin, vec3 wi) {
    return l.kind == LIGHT_DIRECTIONAL ? occluded_ray_from(origin, wi) : occluded_from(origin, l.position);
}

// A hit's material at least `min_roughness` rough, the reflecting surface's (path
// regularisation, Kaplanyan & Dachsbacher 2013): a rough pixel's ray lands anywhere in a wide
// lobe, and a glossy hit's highlight of a point light caught by one ray in thousands is a
// firefly of thousands of times the pixel's mean (pica_pica's bulb seen through two
// reflections: one pixel at 2,800 times the reference after four frames, relMSE 0.98).
// Widening the hit's lobe to the pixel's spreads the highlight over the footprint it is seen
// through, as the pixel's own blur would after many frames, and keeps most of its energy (GGX
// is normalised; what the wider lobe sends to grazing angles or past the surface's edge is
// lost: 19 % of a wall's highlight in the worst case of tests/render/raytraced.rs, over 256
// frames). A smooth pixel (a mirror) keeps the hit's sharp highlight, which is then coherent
// across pixels rather than noise.
Surface regularised_hit(TraceRay r, TraceHit h, float min_roughness) {
    Surface s = surface_at(r, h);
    s.mat.roughness = max(s.mat.roughness, min_roughness);
    s.mat.clearcoat_roughness = max(s.mat.clearcoat_roughness, min_roughness);
    return s;
}

// Radiance leaving surface s towards wo but its lights' terms (and, where `specular` is false,
// its specular lobe's light from around): emission, and the sky or environment as unshadowed
// ambient (diffuse from its irradiance, specular from its level prefiltered for the hit's
// roughness), or the probes' light where the file has them.
vec3 ambient_light(Surface s, vec3 wo, bool specular) {
    vec3 sum = s.emission;
    vec3 diffuse = s.mat.diffuse_only ? s.mat.base : s.mat.base * (1.0 - s.mat.metallic);
    vec3 mirror = reflect(-wo, s.ns);
    vec3 diffuse_in = env_irradiance(s.ns, frame.sky.rgb);
    vec3 specular_in = env_filtered(mirror, s.mat.roughness, frame.sky.rgb);
    if (probe_volume.dims.x != 0u) {
        // Where the file has probes, their light stands in for the sky's as the direct pass
        // takes it at the visible surfaces (`--gi probes`): the room's indirect light and, with
        // the sky occluded, the light the emissive surfaces send (no other term of this pass
        // counts them). Without, metal reflecting an indirectly lit room showed it as dark as
        // the sky outside: pica_pica's aluminium alcoves at 55 % of the reference's radiance
        // after 64 frames of `--preset rt-8` (docs/benchmarks/reflection-probes/).
        vec3 n = dot(s.ns, wo) < 0.0 ? -s.ns : s.ns;
        ProbeLight pl = probe_light(probe_volume, s.p, n, wo, true);
        float confidence = clamp(pl.confidence, 0.0, 1.0);
        diffuse_in = mix(diffuse_in, pl.irradiance, confidence);
        // The probes' irradiance about the mirror direction, sharpened as the direct pass's split
        // sum does.
        float ratio = env_sharpness(mirror, specular_in, frame.sky.rgb);
        specular_in = mix(specular_in, pl.mirror * ratio, confidence);
    }
    sum += diffuse_in * diffuse;
    if (specular && !s.mat.diffuse_only) {
        sum += specular_in * fresnel_f0(s.mat);
    }
    return sum;
}

// Whether the specular lobe of a hit is traced once more rather than read from the probes or
// the sky: smooth metal, whose light is all in that lobe and which mirrors its surroundings
// sharply, where the probes' cosine lobe about the mirror direction blurs the room it shows
// (pica_pica's console: its metal deck mirrors the metal panel above it, which mirrors the lit
// room; read from the probes the deck was a third darker than the reference).
bool traced_onwards(Surface s) {
    return !s.mat.diffuse_only && s.mat.metallic >= 0.5 && s.mat.roughness < rt.metal_bounce_roughness;
}

// The lights whose shadow rays at a second hit the shadow pass traces (the first ones), and the
// layer of `refl_lights` that holds that hit's origin, after their terms.
uint second_hit_lights() {
    return min(rt.reflection_lights, REFLECTION_SECOND_HIT_LIGHTS);
}

uint second_origin_layer() {
    return rt.reflection_lights + second_hit_lights();
}

// The lights' terms at hit s seen from wo: those of the first `deferred` lights go unshadowed,
// scaled by `scale`, to `refl_lights` layers `first_layer` + i for the shadow pass (every one
// written: it reads them all); the rest are shadow-tested from `origin` here and summed.
vec3 light_terms(Surface s, vec3 wo, vec3 origin, ivec2 cell, vec3 scale, uint first_layer, uint deferred) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < frame.size.z; i++) {
        vec3 wi;
        vec3 term = light_term(lights[i], s, wo, wi);
        if (i < deferred) {
            imageStore(refl_lights, ivec3(cell, int(first_layer + i)), vec4(term * scale, 0.0));
        } else if (any(greaterThan(term, vec3(0.0))) && !light_occluded(lights[i], origin, wi)) {
            sum += term;
        }
    }
    return sum;
}

// Radiance leaving a second hit towards -r.direction but the shadowed terms of the lights the
// shadow pass handles, which go, scaled by `scale`, to their layers after the first hit's
// (`rt.reflection_lights` + i), and its offset origin to the layer after those (w = 1); any
// further lights' shadow rays are traced here.
vec3 shade_second_hit(TraceRay r, TraceHit h, ivec2 cell, vec3 scale, float min_roughness) {
    Surface s = regularised_hit(r, h, min_roughness);
    vec3 wo = -normalize(r.direction);
    vec3 origin = offset_ray_origin(s.p, s.ng);
    imageStore(refl_lights, ivec3(cell, int(second_origin_layer())), vec4(origin, 1.0));
    return ambient_light(s, wo, true)
        + light_terms(s, wo, origin, cell, scale, rt.reflection_lights, second_hit_lights());
}

// Radiance leaving the hit towards -dir, without the shadowed terms of the lights that the
// shadow pass handles (stored, scaled by `scale`, in their `refl_lights` layers, and a second
// hit's after them); the hit's offset origin goes to `origin`. The hit is regularised to the
// reflecting pixel's roughness (`regularised_hit`). Smooth metal's specular lobe is traced one
// bounce further (`traced_onwards`), the rest reads the probes or the sky (`ambient_light`).
vec3 shade_hit(TraceRay r, TraceHit h, ivec2 cell, vec3 scale, float min_roughness, out vec3 origin) {
    Surface s = regularised_hit(r, h, min_roughness);
    origin = offset_ray_origin(s.p, s.ng);
    vec3 wo = -normalize(r.direction);
    bool onwards = traced_onwards(s);
    vec3 sum = ambient_light(s, wo, !onwards);
    bool second = false;
    if (onwards) {
        vec3 wi;
        vec3 weight = sample_lobe(s.mat, s.ns, s.ng, wo, wi);
        if (any(greaterThan(weight, vec3(0.0)))) {
            TraceRay r2 = make_ray(origin, wi, 0.0, 3.4e38);
            TraceHit h2 = trace(r2, false);
            if (h2.t == NO_HIT) {
                sum += weight * env_radiance(wi, frame.sky.rgb);
            } else {
                sum += weight * shade_second_hit(r2, h2, cell, scale * weight, s.mat.roughness);
                second = true;
            }
        }
    }
    if (!second) {
        imageStore(refl_lights, ivec3(cell, int(second_origin_layer())), vec4(0.0));
    }
    return sum + light_terms(s, wo, origin, cell, scale, 0u, rt.reflection_lights);
}

void main() {
    uvec2 cell = gl_GlobalInvocationID.xy;
    uvec2 cells = (frame.size.xy + rt.reflection_step - 1u) / rt.reflection_step;
    if (any(greaterThanEqual(cell, cells))) {
        return;
    }
    // Half resolution traces the top-left pixel of each 2 × 2 block; the composition upsamples
    // with weights that respect that pixel's surface.
    ivec2 pixel = ivec2(cell * rt.reflection_step);
    vec4 value = vec4(0.0);
    vec4 origin = vec4(0.0);
    Primary s;
    if (primary_at(pixel, s)) {
        vec4 mat = texelFetch(g_material, pixel, 0);
        float roughness = mat.g;
        if (!gbuffer_diffuse_only(mat) && roughness <= rt.max_roughness) {
            seed_rng(pixel, 3u);
            Material m = gbuffer_material(texelFetch(g_albedo, pixel, 0), mat);
            vec3 wi;
            vec3 scale = sample_lobe(m, s.n, s.ng, s.v, wi);
            vec3 radiance = vec3(0.0);
            if (any(greaterThan(scale, vec3(0.0)))) {
                TraceRay r = make_ray(offset_ray_origin(s.p, s.ng), wi, 0.0, 3.4e38);
                TraceHit hit = trace(r, false);
                if (hit.t == NO_HIT) {
                    radiance = scale * env_radiance(wi, frame.sky.rgb);
                } else {
                    vec3 o;
                    radiance = scale * shade_hit(r, hit, ivec2(cell), scale, roughness, o);
                    origin = vec4(o, 1.0);
                }
            }
            if (any(isnan(radiance)) || any(isinf(radiance))) {
                radiance = vec3(0.0);
            }
            value = vec4(radiance, 1.0);
        }
    }
    imageStore(refl_partial, ivec2(cell), value);
    imageStore(refl_origin, ivec2(cell), origin);
}
