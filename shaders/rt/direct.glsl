// Direct light of emissive surfaces at the visible surface (`--direct ris|restir`): resampled
// importance sampling of the emissive triangles (Talbot 2005) with reservoirs reused across
// frames and neighbours (ReSTIR DI, Bitterli et al. 2020), one shadow ray for the sample that
// shades.
//
// A sample y is a point on an emissive triangle: an entry of the emissive-triangle table
// (`emissive`, chosen in proportion to power by an alias table) and two
// numbers that place it uniformly on the triangle. Its source density is the area measure's
// p(y) = P(entry) / area. The target at a surface s is the unshadowed light it sends there,
//   p̂_s(y) = lum(Le(y)) · max(n·wi, 0) · max(−n_l·wi, 0) / d²      (0 below s's geometric plane),
// without the BRDF, so that a neighbour's target can be evaluated from its position and normal
// alone. The shaded value is the full estimator f(wo, wi) · Le · cos_l / d² · V(y) · W.
//
// Reservoirs (one per pixel): the chosen y, its contribution weight W and the candidates M it
// stands for. Combining reservoirs r_i (made at surfaces s_i) at s: each r_i's sample is chosen
// with weight p̂_s(y_i) · W_i · M_i; the result has M = Σ M_i and
//   W = Σ_j w_j / (Z · p̂_s(y)),   Z = Σ_i M_i over the inputs whose surface could have made y
// (p̂_{s_i}(y) > 0): the 1/Z rule of Bitterli et al. (their Algorithm 6), unbiased as far as
// the targets' supports go. Visibility is not in the target: a neighbour that sees y occluded
// still counts in Z, which darkens by at most the fraction of such neighbours near shadow edges
// (bias-bounded; inputs are kept to surfaces within 2 % of the view distance of s's plane and 25°
// of its normal, which keeps that fraction small). The sample that shades is tested with its own
// shadow ray, so no light leaks through an occluder.
//
// Reuse runs while the running mean of a still camera is young (`REUSE_FRAMES`).
//
// Two kernels (`direct_candidates.comp`, then `direct_reuse.comp`):
// 1. per pixel, `rt.direct_candidates` candidates from the table, one chosen by RIS; with reuse
//    its shadow ray is traced and an occluded choice keeps weight 0 (visibility reuse); then the
//    previous frame's reservoir at the reprojected pixel joins it, its M capped at
//    `rt.direct_temporal` times the candidates, where its surface matches (temporal reuse);
// 2. `rt.direct_spatial` reservoirs of random neighbours within a radius join it where their
//    surfaces match (spatial reuse); the survivor's shadow ray is traced, it shades the pixel,
//    and it is kept, with its surface, for the next frame.
//
// The includer includes hybrid.glsl first. Shadow rays go through the BVH, or through the
// binary line space when the includer defines DIRECT_LS_EXACT (`--shadows linespace`: false,
// exact triangle tests in the cells at the rays' ends only; true, in every filled cell), as the
// analytic lights' shadow feelers do (shadows_linespace.glsl).
#ifndef KILN_DIRECT_GLSL
#define KILN_DIRECT_GLSL

#include "../common/reproject.glsl"
#ifdef DIRECT_LS_EXACT
#define LS_BINDING 36
#include "../common/linespace.glsl"
#endif

uint emitter_count() {
    return rt.emitters;
}

bool emitter_occluded(vec3 from, vec3 ng, vec3 to) {
#ifdef DIRECT_LS_EXACT
    return ls_occluded(from, ng, to, DIRECT_LS_EXACT);
#else
    return occluded(from, ng, to);
#endif
}

bool emitter_occluded_dir(vec3 from, vec3 ng, vec3 dir) {
#ifdef DIRECT_LS_EXACT
    return ls_occluded_dir(from, ng, dir, DIRECT_LS_EXACT);
#else
    return occluded_ray(from, ng, dir);
#endif
}

#include "../common/emitters.glsl"

const uint NO_ENTRY = 0xffffffffu;

struct Reservoir {
    uint entry;   // emissive-table entry, NO_ENTRY for none
    vec2 xi;      // where on its triangle (as `emissive_point` reads it)
    float w_sum;  // while streaming: the sum of the inputs' weights
    float W;      // the contribution weight
    float M;      // candidates it stands for
};

Reservoir empty_reservoir() {
    return Reservoir(NO_ENTRY, vec2(0.0), 0.0, 0.0, 0.0);
}

uvec4 pack_reservoir(Reservoir r) {
    return uvec4(r.entry, packUnorm2x16(r.xi), floatBitsToUint(r.W), uint(r.M));
}

Reservoir unpack_reservoir(uvec4 v) {
    Reservoir r = Reservoir(v.x, unpackUnorm2x16(v.y), 0.0, uintBitsToFloat(v.z), float(v.w));
    if (r.entry >= rt.emissive || !(r.W >= 0.0) || isinf(r.W)) {
        return empty_reservoir();
    }
    return r;
}

// Streams one input of weight w into r; true when it was chosen.
bool stream(inout Reservoir r, uint entry, vec2 xi, float w) {
    if (!(w > 0.0) || isinf(w)) {
        return false;
    }
    r.w_sum += w;
    if (rnd() * r.w_sum < w) {
        r.entry = entry;
        r.xi = xi;
        return true;
    }
    return false;
}

// An emissive-table entry, in proportion to power, by Walker's alias method: one or two reads
// whatever the number of emitters (a binary search over 10,000 took 14 dependent reads per
// candidate).
uint choose_emissive(float xi) {
    float x = xi * float(rt.emissive);
    uint i = min(uint(x), rt.emissive - 1u);
    return x - float(i) < emissive[i].keep ? i : emissive[i].alias;
}

// The point at xi on the triangle of table entry `entry`, as `emissive_point` places it, from
// the entry alone (the material is read only for an emissive texture).
EmissivePoint entry_point(uint entry, vec2 xi) {
    GpuEmissive e = emissive[entry];
    uint tri = e.triangle & EMISSIVE_TRIANGLE_MASK;
    uint texture = (e.triangle & EMISSIVE_TEXTURED) != 0u ? materials[tri_materials[tri]].emissive_texture : NO_TEXTURE;
    return point_on_emitter(e.p0, e.e1, e.e2, e.emission, texture, (e.triangle & EMISSIVE_DOUBLE_SIDED) != 0u, tri, xi);
}

LightPoint light_point(uint entry, vec2 xi, vec3 p) {
    return seen_from(entry_point(entry, xi), p);
}

// p̂ at a surface (point p, shading normal n, geometric normal ng) for a sample it sees as lp.
float target_of(LightPoint lp, vec3 n, vec3 ng) {
    if (!lp.valid || dot(ng, lp.wi) <= 0.0) {
        return 0.0;
    }
    return luminance(lp.le) * max(dot(n, lp.wi), 0.0) * lp.cos_l / lp.d2;
}

float target_at(uint entry, vec2 xi, vec3 p, vec3 n, vec3 ng) {
    return target_of(light_point(entry, xi, p), n, ng);
}

// Whether a surface (q, normal nq) is close enough to s's to share its reservoirs: within 2 % of
// the view distance of s's tangent plane, normals within 25°.
bool similar_surface(Primary s, vec3 q, vec3 nq) {
    float scale = max(length(frame.camera.xyz - s.p), 1e-30);
    return abs(dot(q - s.p, s.n)) <= 0.02 * scale && dot(s.n, nq) >= 0.9;
}

bool visible(Primary s, LightPoint lp) {
    return rt.direct_visibility == 0u || !emitter_occluded(s.p, s.ng, lp.target);
}

// `rt.direct_candidates` candidates at s, one chosen by RIS.
Reservoir initial_candidates(Primary s) {
    Reservoir r = empty_reservoir();
    float chosen_target = 0.0;
    for (uint i = 0u; i < rt.direct_candidates; i++) {
        uint entry = choose_emissive(rnd());
        float x = rnd();
        // Quantised as the reservoir stores it, so that a reused sample is the one weighed here.
        vec2 xi = unpackUnorm2x16(packUnorm2x16(vec2(x, rnd())));
        LightPoint lp = light_point(entry, xi, s.p);
        float t = target_of(lp, s.n, s.ng);
        float source = emissive[entry].pdf / max(lp.area, 1e-37);
        if (stream(r, entry, xi, t / source)) {
            chosen_target = t;
        }
    }
    r.M = float(rt.direct_candidates);
    r.W = chosen_target > 0.0 ? r.w_sum / (r.M * chosen_target) : 0.0;
    return r;
}

// One input of a combination: a reservoir and the surface it was made at.
struct Input {
    Reservoir r;
    vec3 p;
    vec3 n;
    vec3 ng;
};

// At most the pixel's own reservoir and 8 neighbours' (`--direct-spatial` ≤ 8). A global array:
// passed by value it was copied into local memory on every call (measured: the spatial kernel
// took 1.0 ms at 1600 × 900 on an H100 with 4 neighbours).
const uint MAX_INPUTS = 9u;
Input inputs[MAX_INPUTS];

// Combines `count` inputs at s (the 1/Z rule above). inputs[0] is s's own.
Reservoir combine(Primary s, uint count) {
    Reservoir out_r = empty_reservoir();
    float chosen_target = 0.0;
    float m = 0.0;
    for (uint i = 0u; i < count; i++) {
        Reservoir r = inputs[i].r;
        m += r.M;
        if (r.entry == NO_ENTRY || r.W <= 0.0) {
            continue;
        }
        float t = target_at(r.entry, r.xi, s.p, s.n, s.ng);
        if (stream(out_r, r.entry, r.xi, t * r.W * r.M)) {
            chosen_target = t;
        }
    }
    out_r.M = m;
    if (out_r.entry == NO_ENTRY || chosen_target <= 0.0) {
        out_r.W = 0.0;
        return out_r;
    }
    // The chosen point once; each input's surface sees it from where it is.
    EmissivePoint y = entry_point(out_r.entry, out_r.xi);
    float z = 0.0;
    for (uint i = 0u; i < count; i++) {
        bool could = i == 0u || target_of(seen_from(y, inputs[i].p), inputs[i].n, inputs[i].ng) > 0.0;
        z += could ? inputs[i].r.M : 0.0;
    }
    out_r.W = z > 0.0 ? out_r.w_sum / (z * chosen_target) : 0.0;
    return out_r;
}

// Frames of a still camera's running mean after which reuse stops: reuse trades a small bias
// (the 1/Z rule's, above) and correlation between frames for less noise in each frame; once the
// mean holds REUSE_FRAMES frames, plain RIS converges faster and without bias, and the reused
// frames' bias decays as REUSE_FRAMES / frames. (With a reprojected history every frame
// reuses.)
const uint REUSE_FRAMES = 8u;

bool reusing() {
    return rt.accumulated < REUSE_FRAMES;
}

// The reversed-Z depth of a world point (what the G-buffer holds there).
float depth_of(vec3 p) {
    vec4 clip = frame.view_proj * vec4(p, 1.0);
    return clip.z / clip.w;
}

vec4 surface_record(Primary s) {
    return vec4(s.p, uintBitsToFloat(packHalf2x16(oct_encode(s.n))));
}

void candidates_main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    Primary s;
    if (rt.emissive == 0u || !primary_at(pixel, s)) {
        imageStore(reservoirs_now, pixel, pack_reservoir(empty_reservoir()));
        return;
    }
    seed_rng(pixel, 7u);
    Reservoir r = initial_candidates(s);
    bool reuse = reusing() && (rt.direct_temporal > 0u || rt.direct_spatial > 0u);
    if (reuse && r.entry != NO_ENTRY && r.W > 0.0 && !visible(s, light_point(r.entry, r.xi, s.p))) {
        r.W = 0.0;
    }
    vec2 at;
    float depth_then;
    if (reusing() && rt.direct_temporal > 0u && reproject_pixel(pixel, depth_of(s.p), at, depth_then)) {
        ivec2 then = clamp(ivec2(floor(at)), ivec2(0), ivec2(frame.size.xy) - 1);
        Reservoir prev = unpack_reservoir(imageLoad(reservoirs_then, then));
        vec4 surf = imageLoad(surfaces_then, then);
        vec3 n_then = oct_decode(unpackHalf2x16(floatBitsToUint(surf.w)));
        if (prev.M > 0.0 && similar_surface(s, surf.xyz, n_then)) {
            prev.M = min(prev.M, float(rt.direct_temporal * rt.direct_candidates));
            inputs[0] = Input(r, s.p, s.n, s.ng);
            // The previous surface's geometric normal is not kept: its shading normal stands in.
            inputs[1] = Input(prev, surf.xyz, n_then, n_then);
            r = combine(s, 2u);
        }
    }
    imageStore(reservoirs_now, pixel, pack_reservoir(r));
}

// The BRDF times the cosine at the visible surface: its diffuse part alone where the ray-traced
// reflections carry the specular lobe (they see the emitters along it).
vec3 direct_brdf(Primary s, ivec2 pixel, vec3 wi) {
    vec4 mat = texelFetch(g_material, pixel, 0);
    Surface surf;
    surf.p = s.p;
    surf.ng = s.ng;
    surf.ns = s.n;
    surf.nc = s.n;
    surf.mat = gbuffer_material(texelFetch(g_albedo, pixel, 0), mat);
    bool traced_specular = (frame.size.w & FRAME_RT_REFLECTIONS) != 0u && !surf.mat.diffuse_only
        && surf.mat.roughness <= rt.max_roughness;
    // Light from behind a transmitting surface comes through its transmitted lobe, which no
    // reflection carries.
    if (!traced_specular || dot(s.ng, wi) < 0.0) {
        return brdf_cos(surf, s.v, wi);
    }
    float n_l = dot(s.n, wi);
    if (n_l <= 0.0 || dot(s.ng, wi) <= 0.0 || dot(s.n, s.v) <= 0.0) {
        return vec3(0.0);
    }
    vec3 h = normalize(s.v + wi);
    vec3 f = fresnel_schlick(fresnel_f0(surf.mat), fresnel_f90(surf.mat), max(dot(s.v, h), 0.0));
    return (1.0 - f) * (1.0 - surf.mat.metallic) * (1.0 - surf.mat.transmission) * surf.mat.base / PI * n_l;
}

void reuse_main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    Primary s;
    vec3 l = vec3(0.0);
    if (rt.emissive > 0u && primary_at(pixel, s)) {
        seed_rng(pixel, 8u);
        inputs[0] = Input(unpack_reservoir(imageLoad(reservoirs_now, pixel)), s.p, s.n, s.ng);
        uint count = 1u;
        float radius = max(3.0, 0.015 * float(max(frame.size.x, frame.size.y)));
        uint taps = reusing() ? min(rt.direct_spatial, MAX_INPUTS - 1u) : 0u;
        for (uint i = 0u; i < taps; i++) {
            float a = 2.0 * PI * rnd();
            float rr = radius * sqrt(rnd());
            ivec2 q = pixel + ivec2(round(rr * vec2(cos(a), sin(a))));
            Primary o;
            if (q == pixel || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(uvec2(q), frame.size.xy))
                || !primary_at(q, o) || !similar_surface(s, o.p, o.n)) {
                continue;
            }
            inputs[count] = Input(unpack_reservoir(imageLoad(reservoirs_now, q)), o.p, o.n, o.ng);
            count++;
        }
        Reservoir r = count > 1u ? combine(s, count) : inputs[0].r;
        if (r.entry != NO_ENTRY && r.W > 0.0) {
            LightPoint lp = light_point(r.entry, r.xi, s.p);
            if (lp.valid && visible(s, lp)) {
                l = direct_brdf(s, pixel, lp.wi) * lp.le * (lp.cos_l / lp.d2 * r.W);
            } else {
                r.W = 0.0;
            }
        }
        if (any(isnan(l)) || any(isinf(l))) {
            l = vec3(0.0);
        }
        imageStore(reservoirs_then, pixel, pack_reservoir(r));
        imageStore(surfaces_then, pixel, surface_record(s));
    } else {
        imageStore(reservoirs_then, pixel, pack_reservoir(empty_reservoir()));
    }
    // Alpha: the square of the demodulated sample's luminance, whose running mean is the second
    // moment the denoiser estimates the noise from (shaders/denoise/).
    float m = luminance(l / demodulator(srgb_to_linear(texelFetch(g_albedo, pixel, 0).rgb)));
    imageStore(rt_direct, pixel, accumulate(imageLoad(rt_direct, pixel), vec4(l, min(m * m, 3.0e38))));
}

#endif
