#version 460
#extension GL_EXT_control_flow_attributes : require
// Tóth & Umenhoffer's shadow-map ray march (`--media toth`, seed 002 §7) with the seed's errata
// fixed: each pixel's view ray, from the camera to its surface (or out of the media for the
// sky), is cut into `tc.samples` equal steps over its part inside the media, sampled at their
// midpoints (a fixed count, never a sample behind the camera), in world space with world
// distances; every sample weighs its step length Δs (the listing's missing factor):
//
//   S = Σ_i Δs · e^{−τ(camera, x_i)} · Σ_lights σs(x_i) p(θ) · E(x_i) · V(x_i) · e^{−τ(x_i, light)},
//
// E the light's unoccluded irradiance at x_i (inverse square for point, spot and rect lights,
// a rect as a point of intensity L·A·cos), V its shadow map's test at x_i (the compiler's baked
// maps: 2D for directional and spot lights, cube for point and rect lights; a light without one
// is unshadowed), p the normalised Henyey–Greenstein (the medium's g) or Rayleigh phase function
// and τ the optical depth through the media boxes, analytic. The transmittances are computed per
// sample, not accumulated, so samples are independent: interleaved sampling splits the samples
// over a block × block tile (each pixel takes every block²-th one), and `toth/blur.comp` joins
// the tile back together. Output: the pixel's samples' sum (rgb) and how many it took (alpha).
#include "../common/layout.glsl"
#include "../common/lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, std430) readonly buffer Lights { GpuLight lights[]; };
layout(set = 0, binding = 2, std430) readonly buffer Shadows { GpuShadow shadows[]; };
layout(set = 0, binding = 3) uniform sampler2D shadow_2d[MAX_SHADOW_MAPS];
layout(set = 0, binding = 4) uniform samplerCube shadow_cube[MAX_SHADOW_MAPS];
layout(set = 0, binding = 5, std430) readonly buffer Media { GpuMedium media[]; };
layout(set = 0, binding = 6) uniform sampler2D g_depth;
layout(set = 0, binding = 7, rgba16f) uniform writeonly image2D scatter;
layout(push_constant) uniform Push { TothConstants tc; };

#include "../common/pixel.glsl"
#include "../common/media.glsl"

// Whether point p of the medium sees the light of 2D shadow map s: one nearest texel, the
// recommended bias of 1.5 footprints (FORMAT.md, "SHDW"; no normal offset in a medium). Outside
// the map: lit.
float lit_2d(GpuShadow s, vec3 p) {
    bool ortho = s.projection == SHADOW_ORTHOGRAPHIC;
    vec3 to = p - s.origin;
    float d = ortho ? dot(to, s.direction) : length(to);
    vec4 clip = s.view_proj * vec4(p, 1.0);
    vec2 ndc = clip.xy / clip.w;
    if (clip.w <= 0.0 || any(greaterThan(abs(ndc), vec2(1.0)))) {
        return 1.0;
    }
    vec2 uv = vec2(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    ivec2 texel = clamp(ivec2(uv * float(s.resolution)), ivec2(0), ivec2(int(s.resolution) - 1));
    float footprint = ortho ? s.texel : d * s.texel;
    return d <= texelFetch(shadow_2d[s.slot], texel, 0).r + 1.5 * footprint ? 1.0 : 0.0;
}

// The same for a cube map.
float lit_cube(GpuShadow s, vec3 p) {
    vec3 to = p - s.origin;
    float d = length(to);
    return d <= textureLod(shadow_cube[s.slot], to, 0.0).r + 1.5 * d * s.texel ? 1.0 : 0.0;
}

float visibility(GpuLight l, vec3 p) {
    if (l.shadow < 0) {
        return 1.0;
    }
    GpuShadow s = shadows[l.shadow];
    return s.projection == SHADOW_CUBE ? lit_cube(s, p) : lit_2d(s, p);
}

// Rayleigh: 3/(16π) (1 + cos² θ) (the seed's listing returned cos² θ, its erratum 5).
float rayleigh(float cos_theta) {
    return 3.0 / (16.0 * 3.14159265358979) * (1.0 + cos_theta * cos_theta);
}

// σs·p summed over the media holding p, for light arriving along −wl seen along −d.
vec3 scattering(vec3 p, vec3 wl, vec3 d) {
    vec3 sum = vec3(0.0);
    float cos_theta = dot(wl, d);
    for (uint m = 0u; m < tc.media; m++) {
        if (all(greaterThanEqual(p, media[m].min.xyz)) && all(lessThanEqual(p, media[m].max.xyz))) {
            float phase = tc.phase == PHASE_RAYLEIGH ? rayleigh(cos_theta) : hg(media[m].min.w, cos_theta);
            sum += media[m].sigma_s.rgb * phase;
        }
    }
    return sum;
}

// What the media at x scatter towards the camera along −d per unit length, from every light.
vec3 in_scattered(vec3 x, vec3 d) {
    vec3 sum = vec3(0.0);
    [[dont_unroll]] for (uint i = 0u; i < frame.size.z; i++) {
        GpuLight l = lights[i];
        vec3 wl;
        float dist;
        vec3 e;
        if (!light_at_point(l, x, wl, dist, e)) {
            continue;
        }
        if (all(equal(e, vec3(0.0))) || visibility(l, x) == 0.0) {
            continue;
        }
        sum += scattering(x, wl, d) * e * exp(-optical_depth(tc.media, x, wl, 0.0, dist));
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
    // The view ray's part inside the media: from the first entry to the last exit.
    float t0 = SKY_DISTANCE, t1 = 0.0;
    for (uint m = 0u; m < tc.media; m++) {
        vec2 span = box_span(media[m].min.xyz, media[m].max.xyz, o, d, 0.0, t_surface);
        if (span.y > span.x) {
            t0 = min(t0, span.x);
            t1 = max(t1, span.y);
        }
    }
    vec3 sum = vec3(0.0);
    if (t1 > t0) {
        uint n = max(tc.samples, 1u);
        uint block = max(tc.block, 1u);
        uint stride = block * block;
        uint first = uint(pixel.x) % block + block * (uint(pixel.y) % block);
        float ds = (t1 - t0) / float(n);
        uint taken = 0u;
        [[dont_unroll]] for (uint i = first; i < n; i += stride) {
            float t = t0 + (float(i) + 0.5) * ds;
            vec3 x = o + d * t;
            sum += exp(-optical_depth(tc.media, o, d, 0.0, t)) * in_scattered(x, d);
            taken++;
        }
        sum *= ds;
        imageStore(scatter, pixel, vec4(sum, float(taken)));
        return;
    }
    imageStore(scatter, pixel, vec4(0.0));
}
