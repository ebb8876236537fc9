// Emitters as next-event estimation sees them: one emitter of the table (`GpuEmitter`s: analytic
// lights and emissive triangles, chosen in proportion to their power) sampled per vertex, the
// power heuristic against BRDF sampling, the rect lights a BRDF-sampled ray crosses, and the
// weight of an emissive triangle a BRDF-sampled ray hits. One copy for the reference path tracer
// and the GI pass.
//
// The includer declares the storage buffers `emitters` (GpuEmitter), `tri_emitter` (int per
// triangle, leaf order: its entry in `emitters` or -1), `lights` (GpuLight) and those scene.glsl
// reads, includes scene.glsl first, and defines before including this file:
//   uint emitter_count()                                         entries of `emitters`
//   bool emitter_occluded(vec3 from, vec3 ng, vec3 to)           shadow ray of a segment
//   bool emitter_occluded_dir(vec3 from, vec3 ng, vec3 dir)      shadow ray towards infinity
// (`from` on a surface of geometric normal `ng`, not yet offset: scene.glsl's `occluded` and
// `occluded_ray` are such functions). An includer with participating media also defines
// EMITTER_TRANSMITTANCE and
//   vec3 emitter_transmittance(vec3 from, EmitterSample es)      along a shadow ray
//   vec3 emitter_seen_weight(float t)                            a rect light crossed at t
// (declared here, after `EmitterSample`; the includer defines them anywhere in the shader).
#ifndef KILN_EMITTERS_GLSL
#define KILN_EMITTERS_GLSL

// The probability with which the includer chose the emitter table for the next-event
// estimation at hand (and, for `rect_lights_seen` and `triangle_emission_weight`, at the vertex
// the ray left): every light pdf is multiplied by it. The reference path tracer, which defines
// EMITTER_CHOICES and sets them, shares one shadow ray per surface vertex between the table and
// the environment; for the GI pass both are the constant 1.
#ifdef EMITTER_CHOICES
float emitter_choice = 1.0;
// The same for the environment (`sample_environment`, `environment_seen_weight`).
float env_choice = 1.0;
#else
const float emitter_choice = 1.0;
const float env_choice = 1.0;
#endif

float power_heuristic(float a, float b) {
    float a2 = a * a;
    return a2 / max(a2 + b * b, 1e-30);
}

// An entry of the table in proportion to power, by Walker's alias method (GpuEmitter).
uint choose_emitter(float xi) {
    float x = xi * float(emitter_count());
    uint i = min(uint(x), emitter_count() - 1u);
    return x - float(i) < emitters[i].keep ? i : emitters[i].alias;
}

// One emitter of the table sampled from a point: the direction to it, the radiance it sends
// there (point and spot lights: divided by the squared distance; no cosine at the receiver),
// the density of the sample (solid angle; for delta lights, the selection probability), and
// where a shadow ray ends.
struct EmitterSample {
    bool valid;
    vec3 wi;
    vec3 li;
    float pdf;
    bool delta;       // a point, spot or directional light: no MIS
    bool directional; // the shadow ray is unbounded along wi
    vec3 target;      // the shadow ray's end (moved off an emissive triangle)
};

// A point on an emissive triangle, uniform in area for xi uniform in [0, 1)²: where it lies,
// the triangle's unit normal (its winding's) and area, whether its material emits from both
// sides, and the radiance it emits there (the emissive texture included).
struct EmissivePoint {
    vec3 q;
    vec3 nl;
    float area;
    bool double_sided;
    vec3 le;
};

// The point at xi on the triangle p0 + (e1, e2) (triangle `tri`, leaf order, for its texture
// coordinates) of a material emitting `emission` through `texture` (NO_TEXTURE: none).
EmissivePoint point_on_emitter(vec3 p0, vec3 e1, vec3 e2, vec3 emission, uint texture, bool double_sided, uint tri,
                               vec2 xi) {
    float su = sqrt(xi.x);
    float b1 = 1.0 - su, b2 = xi.y * su;
    EmissivePoint ep;
    ep.q = p0 + b1 * e1 + b2 * e2;
    vec3 c = cross(e1, e2);
    ep.area = 0.5 * length(c);
    ep.nl = c / max(2.0 * ep.area, 1e-30);
    ep.double_sided = double_sided;
    ep.le = emission;
    if (texture != NO_TEXTURE) {
        ep.le *= mip0(textures[texture], triangle_uv(tri, b1, b2)).rgb;
    }
    return ep;
}

// The point at xi on emissive triangle `tri` (leaf order), from the BVH's triangles.
EmissivePoint emissive_point(uint tri, vec2 xi) {
    vec3 p0 = bvh_tris[3u * tri].xyz, p1 = bvh_tris[3u * tri + 1u].xyz, p2 = bvh_tris[3u * tri + 2u].xyz;
    GpuMaterialLayout m = materials[tri_materials[tri]];
    return point_on_emitter(p0, p1 - p0, p2 - p0, m.emission, m.emissive_texture,
                            (m.flags & MATERIAL_DOUBLE_SIDED) != 0u, tri, xi);
}

// An emissive point as a surface at p sees it.
struct LightPoint {
    bool valid;   // in front of the emitter's emitting side, at a distance
    vec3 wi;      // towards the point
    float d2;     // squared distance
    float cos_l;  // at the emitter
    vec3 le;      // emitted radiance
    vec3 target;  // the shadow ray's end, moved off the emitter towards p
    float area;   // the triangle's
};

LightPoint seen_from(EmissivePoint ep, vec3 p) {
    LightPoint lp;
    vec3 to = ep.q - p;
    lp.d2 = dot(to, to);
    lp.wi = to * inversesqrt(max(lp.d2, 1e-37));
    lp.cos_l = -dot(ep.nl, lp.wi);
    if (ep.double_sided) {
        lp.cos_l = abs(lp.cos_l);
    }
    lp.le = ep.le;
    lp.area = ep.area;
    lp.valid = lp.cos_l > 0.0 && ep.area > 0.0 && lp.d2 > 0.0;
    // The shadow ray must not reach the emitter's own surface.
    lp.target = offset_ray_origin(ep.q, dot(ep.nl, lp.wi) < 0.0 ? ep.nl : -ep.nl);
    return lp;
}

#ifdef EMITTER_TRANSMITTANCE
vec3 emitter_transmittance(vec3 from, EmitterSample es);
vec3 emitter_seen_weight(float t);
#endif

EmitterSample sample_emitter_light(vec3 origin) {
    EmitterSample es;
    es.valid = false;
    es.delta = true;
    es.directional = false;
    es.li = vec3(0.0);
    es.wi = vec3(0.0, 0.0, 1.0);
    es.target = origin;
    es.pdf = 1.0;
    if (emitter_count() == 0u) {
        return es;
    }
    GpuEmitter e = emitters[choose_emitter(rnd())];
    if (e.kind == EMITTER_TRIANGLE) {
        float xi = rnd();
        LightPoint lp = seen_from(emissive_point(e.index, vec2(xi, rnd())), origin);
        if (!lp.valid) {
            return es;
        }
        es.valid = true;
        es.delta = false;
        es.wi = lp.wi;
        es.li = lp.le;
        es.pdf = emitter_choice * e.pdf * lp.d2 / (lp.cos_l * lp.area);
        es.target = lp.target;
        return es;
    }
    GpuLight l = lights[e.index];
    es.pdf = emitter_choice * e.pdf;
    if (l.kind == LIGHT_DIRECTIONAL) {
        es.wi = -l.direction;
        es.directional = true;
        es.li = l.radiance;
    } else if (l.kind == LIGHT_RECT) {
        vec3 up = cross(l.direction, l.right);
        vec3 q = l.position + l.right * (rnd() - 0.5) * l.width + up * (rnd() - 0.5) * l.height;
        vec3 to = q - origin;
        float d2 = dot(to, to);
        float dist = sqrt(d2);
        es.wi = to / dist;
        es.target = q;
        float cos_l = dot(-es.wi, l.direction);
        float area = l.width * l.height;
        if (cos_l <= 0.0 || area <= 0.0 || (l.range > 0.0 && dist > l.range)) {
            return es;
        }
        es.li = l.radiance;
        es.pdf = emitter_choice * e.pdf * d2 / (cos_l * area);
        es.delta = false;
    } else {
        es.target = l.position;
        vec3 to = l.position - origin;
        float d2 = dot(to, to);
        float dist = sqrt(d2);
        es.wi = to / max(dist, 1e-30);
        if (dist <= 0.0 || (l.range > 0.0 && dist > l.range)) {
            return es;
        }
        float cone = 1.0;
        if (l.kind == LIGHT_SPOT) {
            cone = spot_cone(l, es.wi);
        }
        es.li = l.radiance * cone / d2;
    }
    es.valid = !all(equal(es.li, vec3(0.0)));
    return es;
}

// Whether the shadow ray of `es` from `origin` (on a surface of geometric normal `ng`; zero in
// a medium) is blocked.
bool emitter_blocked(EmitterSample es, vec3 origin, vec3 ng) {
    return es.directional ? emitter_occluded_dir(origin, ng, es.wi) : emitter_occluded(origin, ng, es.target);
}

// Next-event estimation: radiance arriving at s from one emitter (times the BRDF and cosine,
// over the sampling density), times `emitter_transmittance` when the includer defines
// EMITTER_TRANSMITTANCE. `mis`: weighted with the power heuristic against a BRDF-sampled
// continuation that counts the emitters it reaches (`rect_lights_seen`,
// `triangle_emission_weight`); without one, unweighted, the whole of the emitters' light.
vec3 sample_emitter(Surface s, vec3 wo, bool mis) {
    EmitterSample es = sample_emitter_light(s.p);
    if (!es.valid) {
        return vec3(0.0);
    }
    vec3 f = brdf_cos(s, wo, es.wi);
    if (all(equal(f, vec3(0.0))) || emitter_blocked(es, s.p, facing(s.ng, es.wi))) {
        return vec3(0.0);
    }
    float weight = (es.delta || !mis) ? 1.0 : power_heuristic(es.pdf, brdf_pdf(s, wo, es.wi));
    vec3 contribution = f * es.li * weight / es.pdf;
#ifdef EMITTER_TRANSMITTANCE
    contribution *= emitter_transmittance(s.p, es);
#endif
    return contribution;
}

// Rect lights are not geometry: a BRDF-sampled ray sees one when it crosses its rectangle
// from the front before the next surface. Returns the MIS-weighted radiance (`pdf_brdf` 0: a
// ray not sampled from a BRDF, unweighted).
vec3 rect_lights_seen(vec3 origin, vec3 dir, float tmax, float pdf_brdf) {
    vec3 sum = vec3(0.0);
    // The table lists the analytic lights before the emissive triangles (scene/reference.rs),
    // so the loop ends at the first triangle: it reads the lights, not every emitter. (It read
    // all of them: ToyCar's body, 88,837 triangles of an emissive material, made every bounce
    // read 88,837 entries; its reference ran at 0.47 M samples/s on an H200, 123 M without.)
    for (uint i = 0u; i < emitter_count(); i++) {
        GpuEmitter e = emitters[i];
        if (e.kind != EMITTER_LIGHT) {
            break;
        }
        if (lights[e.index].kind != LIGHT_RECT) {
            continue;
        }
        GpuLight l = lights[e.index];
        float t = rect_light_hit(l, origin, dir, tmax);
        if (t < 0.0) {
            continue;
        }
        float denom = dot(dir, l.direction);
        float area = l.width * l.height;
        float pdf_light = emitter_choice * e.pdf * t * t / (-denom * area);
        vec3 seen = l.radiance * (pdf_brdf > 0.0 ? power_heuristic(pdf_brdf, pdf_light) : 1.0);
#ifdef EMITTER_TRANSMITTANCE
        seen *= emitter_seen_weight(t);
#endif
        sum += seen;
    }
    return sum;
}

// The power-heuristic weight of the emission of triangle `tri` (leaf order), hit at distance
// `d` at cosine `cos_l` to its normal by a ray BRDF-sampled with density `pdf_brdf`, against
// `sample_emitter` with `mis` (1 for a ray not sampled from a BRDF, or a triangle not in the
// table).
float triangle_emission_weight(uint tri, float d, float cos_l, float pdf_brdf) {
    int e = tri_emitter[tri];
    if (pdf_brdf <= 0.0 || e < 0) {
        return 1.0;
    }
    vec3 p0 = bvh_tris[3u * tri].xyz, p1 = bvh_tris[3u * tri + 1u].xyz, p2 = bvh_tris[3u * tri + 2u].xyz;
    float area = 0.5 * length(cross(p1 - p0, p2 - p0));
    float pdf_light = emitter_choice * emitters[e].pdf * d * d / max(cos_l * area, 1e-30);
    return power_heuristic(pdf_brdf, pdf_light);
}

#ifdef KILN_ENVIRONMENT_GLSL
// The environment (environment.glsl, included before this file) as an emitter: next-event
// estimation through its sampling table, weighted with the power heuristic against BRDF
// sampling (`mis`), shadowed by a ray towards infinity (and dimmed by the media's
// transmittance with EMITTER_TRANSMITTANCE). Nothing without an environment: the constant sky
// is then found by BRDF-sampled rays alone, as before.
vec3 sample_environment(Surface s, vec3 wo, vec3 sky, bool mis) {
    float pdf;
    vec3 wi = env_sample(vec3(rnd(), rnd(), rnd()), pdf);
    pdf *= env_choice;
    if (!(pdf > 0.0)) {
        return vec3(0.0);
    }
    vec3 f = brdf_cos(s, wo, wi);
    if (all(equal(f, vec3(0.0))) || emitter_occluded_dir(s.p, facing(s.ng, wi), wi)) {
        return vec3(0.0);
    }
    float weight = mis ? power_heuristic(pdf, brdf_pdf(s, wo, wi)) : 1.0;
    vec3 contribution = f * env_radiance(wi, sky) * weight / pdf;
#ifdef EMITTER_TRANSMITTANCE
    EmitterSample es;
    es.valid = true;
    es.directional = true;
    es.delta = false;
    es.wi = wi;
    es.pdf = pdf;
    es.li = vec3(0.0);
    es.target = vec3(0.0);
    contribution *= emitter_transmittance(s.p, es);
#endif
    return contribution;
}

// The power-heuristic weight of the environment seen along unit `dir` by a ray BRDF-sampled
// with density `pdf_brdf` against `sample_environment` (1 for a ray not sampled from a BRDF, or
// without an environment).
float environment_seen_weight(vec3 dir, float pdf_brdf) {
    return (pdf_brdf > 0.0 && env_present()) ? power_heuristic(pdf_brdf, env_choice * env_pdf(dir)) : 1.0;
}
#endif

#endif
