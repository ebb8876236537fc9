#version 460
// Single scattering in participating media by ray marching in world space (`--media march`).
//
// Each pixel's view ray, from the camera to the surface the G-buffer holds (or on to infinity
// for the sky), is clipped to every medium box; the media are composited from the furthest to
// the nearest, each as radiance · T + S, where T = exp(−σt·ℓ) over the ray's length ℓ inside
// the box and S the light it scatters towards the camera:
//
//   S = σs Σ_steps [∫_step e^{−σt·s} ds] · Σ_lights p(θ) · L_light · V · e^{−σt·d_light},
//
// the camera-side transmittance integrated exactly over each step (e^{−σt·a}·(1 − e^{−σt·h})/σt),
// the source at one point of the step, offset per pixel by a 4 × 4 Bayer pattern (interleaved
// sampling: neighbours sample different points, the sum over a block is a finer march). p is
// Henyey–Greenstein; L_light the light's radiance arriving unoccluded (rect lights as a point
// at their centre of intensity L·A·cos); V the light's visibility from the compiler's baked
// volume (trilinear between cell centres; 1 for lights without one, i.e. not casting shadows);
// d_light the distance from the point to the box's boundary towards the light (analytic
// transmittance in a homogeneous box). Works with the light off screen and behind the camera.
// The sky (an environment or the constant sky) adds σs · V_sky,c(x) · L_p(d) per channel c, with
// V_sky the compiler's grids of the sky's light reaching x through the geometry and the medium
// (relative to the sky's whole) and L_p the sky convolved with the phase function: its nine
// spherical harmonics (the environment's irradiance harmonics divided by the cosine lobe's band
// factors 1, 2/3, 1/4) times Henyey–Greenstein's g^l, at d (exact for a uniform sky).
#include "../common/layout.glsl"
#include "../common/lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, std430) readonly buffer Lights { GpuLight lights[]; };
layout(set = 0, binding = 2, std430) readonly buffer Media { GpuMedium media[]; };
layout(set = 0, binding = 3, std430) readonly buffer Volumes { uint volume_words[]; };
layout(set = 0, binding = 4, std430) readonly buffer VolumeOf { int volume_of[]; };
layout(set = 0, binding = 5) uniform sampler2D g_depth;
layout(set = 0, binding = 6, rgba32f) uniform image2D radiance;
layout(push_constant) uniform Push { MarchConstants mc; };
#define ENV_BINDING 7
#include "../common/environment.glsl"   // bindings 7-8

#include "../common/pixel.glsl"
#include "../common/media.glsl"

uint volume_byte(uint at) {
    return (volume_words[at >> 2u] >> (8u * (at & 3u))) & 0xFFu;
}

// Light visibility at p from the volume starting at byte `base` over box [lo, hi]: trilinear
// between cell centres, clamped at the outer half cells.
float visibility(uint base, vec3 lo, vec3 hi, vec3 p) {
    uvec3 dims = uvec3(mc.dims_x, mc.dims_y, mc.dims_z);
    vec3 f = clamp((p - lo) / (hi - lo), 0.0, 1.0) * vec3(dims) - 0.5;
    vec3 c = clamp(f, vec3(0.0), vec3(dims) - 1.0);
    uvec3 i0 = uvec3(floor(c));
    uvec3 i1 = min(i0 + 1u, dims - 1u);
    vec3 w = c - vec3(i0);
    float v = 0.0;
    for (uint k = 0u; k < 8u; k++) {
        uvec3 pick = uvec3(k & 1u, (k >> 1u) & 1u, (k >> 2u) & 1u);
        uvec3 i = mix(i0, i1, bvec3(pick));
        vec3 wk = mix(1.0 - w, w, vec3(pick));
        v += wk.x * wk.y * wk.z * float(volume_byte(base + i.x + dims.x * (i.y + dims.y * i.z)));
    }
    return v / 255.0;
}

// The sky convolved with Henyey–Greenstein of anisotropy g, towards the camera along d: the light
// scattered towards −d per unit σs from a uniform sphere of the sky (the constant sky without an
// environment).
vec3 sky_phase(vec3 d, float g) {
    if (!env_present()) {
        return frame.sky.rgb;
    }
    // The harmonics hold the irradiance over π, band l scaled by A_l = 1, 2/3, 1/4; the phase
    // function's own band factors are g^l: band l scaled by g^l / A_l. Light arriving from ω
    // (towards the sky) scatters towards the camera at cos θ = ω · d (both travel directions
    // negated), so the convolution is evaluated at d.
    return env_harmonics(d, vec3(1.0, 1.5 * g, 4.0 * g * g));
}

// The light medium m scatters towards the camera at p (per unit σs·length, before the camera-
// side transmittance): Σ lights p(θ) · L · V · e^{−σt·d_light}.
vec3 in_scattered(uint m, vec3 p, vec3 d) {
    vec3 lo = media[m].min.xyz, hi = media[m].max.xyz;
    vec3 sigma_t = medium_sigma_t(m);
    float g = media[m].min.w;
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < frame.size.z; i++) {
        GpuLight l = lights[i];
        vec3 wl;
        float dist;
        vec3 li;
        if (!light_at_point(l, p, wl, dist, li)) {
            continue;
        }
        if (all(equal(li, vec3(0.0)))) {
            continue;
        }
        float v = 1.0;
        if (m == mc.volume_medium && i < mc.lights && volume_of[i] >= 0) {
            v = visibility(uint(volume_of[i]), lo, hi, p);
        }
        vec2 out_span = box_span(lo, hi, p, wl, 0.0, dist);
        float inside = max(out_span.y - out_span.x, 0.0);
        sum += hg(g, dot(wl, d)) * li * v * exp(-sigma_t * inside);
    }
    if (m == mc.volume_medium && mc.sky_volume != 0xFFFFFFFFu) {
        uint stride = (mc.dims_x * mc.dims_y * mc.dims_z + 3u) & ~3u;
        vec3 v = vec3(visibility(mc.sky_volume, lo, hi, p), visibility(mc.sky_volume + stride, lo, hi, p),
                      visibility(mc.sky_volume + 2u * stride, lo, hi, p));
        sum += v * sky_phase(d, g);
    }
    return sum;
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    vec2 at = vec2(pixel) + 0.5;
    vec3 o = pixel_origin(at);
    vec3 d = normalize(pixel_ray(at));
    float t_surface = surface_distance(at, texelFetch(g_depth, pixel, 0).r, o, d);
    // 4 × 4 Bayer order: where in its step each pixel samples the source.
    const uint BAYER[16] = uint[16](0u, 8u, 2u, 10u, 12u, 4u, 14u, 6u, 3u, 11u, 1u, 9u, 15u, 7u, 13u, 5u);
    float jitter = (float(BAYER[(pixel.x & 3) + 4 * (pixel.y & 3)]) + 0.5) / 16.0;
    vec3 l = imageLoad(radiance, pixel).rgb;
    // Media from the furthest entry to the nearest.
    float last = SKY_DISTANCE * 2.0;
    for (uint pass = 0u; pass < mc.media; pass++) {
        uint m = 0xFFFFFFFFu;
        float entry = -1.0;
        vec2 span = vec2(0.0);
        for (uint k = 0u; k < mc.media; k++) {
            vec2 s = box_span(media[k].min.xyz, media[k].max.xyz, o, d, 0.0, t_surface);
            if (s.y > s.x && s.x < last && s.x > entry) {
                m = k;
                entry = s.x;
                span = s;
            }
        }
        if (m == 0xFFFFFFFFu) {
            break;
        }
        last = entry;
        vec3 sigma_t = medium_sigma_t(m);
        vec3 sigma_s = media[m].sigma_s.rgb;
        float len = span.y - span.x;
        float h = len / float(max(mc.steps, 1u));
        vec3 scattered = vec3(0.0);
        for (uint i = 0u; i < max(mc.steps, 1u); i++) {
            float a = float(i) * h;
            // ∫ over the step of e^{−σt s} ds, exactly: e^{−σt a} · h · (1 − e^{−x})/x, x = σt h
            // (its series where x is too small for the difference to keep its digits).
            vec3 x = sigma_t * h;
            vec3 ratio = mix((1.0 - exp(-x)) / max(x, vec3(1e-30)), 1.0 - 0.5 * x, lessThan(x, vec3(1e-3)));
            vec3 weight = exp(-sigma_t * a) * h * ratio;
            vec3 p = o + d * (span.x + a + jitter * h);
            scattered += weight * in_scattered(m, p, d);
        }
        l = l * exp(-sigma_t * len) + sigma_s * scattered;
    }
    imageStore(radiance, pixel, vec4(l, 1.0));
}
