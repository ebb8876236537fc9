#version 460
#extension GL_EXT_control_flow_attributes : require
// Direct light and composition: every analytic light over the G-buffer (through thin-walled
// transmitting surfaces from behind too), shadowed by the baked
// shadow maps (PCF; PCSS for rect lights) or by the ray-traced visibility, the emissive
// triangles' light from the direct-light image (`--direct`), plus the sky or environment
// through the split-sum table (its diffuse part times the ray-traced AO, or replaced by the
// ray-traced GI; its specular part replaced by the ray-traced reflections where they were
// traced, or blended with the screen-space reflections' radiance by their confidence; with
// probes, their irradiance along the mirror direction stands in for the sky's radiance there) and
// emission.
// Output: linear scene radiance (before exposure and tone mapping).
#include "../common/layout.glsl"
#include "../common/packing.glsl"
#include "../common/brdf.glsl"
#include "../common/dielectric.glsl"
#include "../common/lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Specialization (DirectPass::new, SPEC_INPUTS): whether the frame's techniques can provide each
// input, and whether the scene has rect lights. The code for what cannot happen is left out of
// the pipeline, which halved the driver's cold compile of this pass; a pipeline made without
// constants has every path.
layout(constant_id = 1) const bool DIRECT_RT_SHADOWS = true;
layout(constant_id = 2) const bool DIRECT_AO = true;
layout(constant_id = 3) const bool DIRECT_RT_REFLECTIONS = true;
layout(constant_id = 4) const bool DIRECT_GI = true;
layout(constant_id = 5) const bool DIRECT_SCREEN_REFLECTIONS = true;
layout(constant_id = 6) const bool DIRECT_MEDIA = true;
layout(constant_id = 7) const bool DIRECT_RECT_LIGHTS = true;
layout(constant_id = 8) const bool DIRECT_EMISSIVE = true;
layout(constant_id = 9) const bool DIRECT_PROBE_SPECULAR = true;

// Shadow maps: MAX_SHADOW_MAPS (layout.glsl) of each kind, indexed by `GpuShadow::slot`.
// The shadow tap loops are [[dont_unroll]]: each tap samples through a dynamically indexed
// sampler array, which CPU drivers (lavapipe) expand into one sampling routine per array element;
// unrolling multiplied that by 16 and took lavapipe 26 s to compile.
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, std430) readonly buffer Lights { GpuLight lights[]; };
layout(set = 0, binding = 2, std430) readonly buffer Shadows { GpuShadow shadows[]; };
layout(set = 0, binding = 3) uniform sampler2D brdf_lut;
layout(set = 0, binding = 4) uniform sampler2D shadow_2d[MAX_SHADOW_MAPS];
layout(set = 0, binding = 5) uniform samplerCube shadow_cube[MAX_SHADOW_MAPS];
layout(set = 0, binding = 6) uniform sampler2D g_depth;
layout(set = 0, binding = 7) uniform sampler2D g_normal;
layout(set = 0, binding = 8) uniform sampler2D g_albedo;
layout(set = 0, binding = 9) uniform sampler2D g_material;
layout(set = 0, binding = 10) uniform sampler2D g_emission;
#include "../common/pixel.glsl"
layout(set = 0, binding = 11, rgba32f) uniform writeonly image2D radiance_out;
layout(set = 0, binding = 12, r32f) uniform readonly image2DArray rt_shadows;
layout(set = 0, binding = 13, r32f) uniform readonly image2D rt_ao;
// Ray-traced reflections (rgb, a > 0 where traced) or, with FRAME_SCREEN_REFLECTIONS, the
// screen-space ones (rgb the incoming radiance along the mirror direction, a the confidence).
layout(set = 0, binding = 14, rgba32f) uniform readonly image2D rt_reflections;
layout(set = 0, binding = 15, rgba32f) uniform readonly image2D rt_gi;
// Participating media between surfaces and lights (`frame.sky.w` boxes: with a media technique).
layout(set = 0, binding = 16, std430) readonly buffer Media { GpuMedium media[]; };
#include "../common/media.glsl"
// The light of the emissive triangles at each pixel's surface (`--direct`: rgb, reflected
// towards the camera, shadowed as its technique says).
layout(set = 0, binding = 17, rgba32f) uniform readonly image2D rt_direct;
// The environment (bindings 18-19): the sky seen, its irradiance harmonics and prefiltered levels
// (the constant sky without one).
#define ENV_BINDING 18
#include "../common/environment.glsl"
// The probes' irradiance along each pixel's mirror direction (FRAME_PROBE_SPECULAR: `--gi probes`).
layout(set = 0, binding = 20, rgba16f) uniform readonly image2D probe_specular;
// The first pixel of the dispatch: (0, 0) over the whole frame; the see-through layer's screen
// area (passes/see_through.rs) where the pass lights that layer.
layout(push_constant) uniform Origin { uvec2 origin; };

// A Vogel spiral of 16 taps in the unit disk.
vec2 tap(int i, float angle) {
    float r = sqrt((float(i) + 0.5) / 16.0);
    float theta = float(i) * 2.39996323 + angle;
    return r * vec2(cos(theta), sin(theta));
}

float hash(uvec2 p) {
    uint h = p.x * 1664525u + p.y * 1013904223u;
    h ^= h >> 16; h *= 0x7feb352du; h ^= h >> 15;
    return float(h) / 4294967296.0;
}

// Recommended bias (FORMAT.md, "SHDW"): 1.5 footprints plus one per unit of slope tangent.
float shadow_bias(float footprint, float cos_theta) {
    float tan_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / max(cos_theta, 1e-3);
    return footprint * (1.5 + min(tan_theta, 10.0));
}

// Orthographic or perspective map: 16-tap PCF over a 1.5-texel radius.
float shadow_2d_factor(GpuShadow s, vec3 p, vec3 n, vec3 l, float angle) {
    vec3 to = p - s.origin;
    float d = s.projection == SHADOW_ORTHOGRAPHIC ? dot(to, s.direction) : length(to);
    float footprint = s.projection == SHADOW_ORTHOGRAPHIC ? s.texel : d * s.texel;
    vec3 q = p + n * footprint;
    vec4 clip = s.view_proj * vec4(q, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    if (clip.w <= 0.0 || any(greaterThan(abs(ndc.xy), vec2(1.0)))) {
        return 1.0;
    }
    vec2 uv = vec2(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    float dq = s.projection == SHADOW_ORTHOGRAPHIC ? dot(q - s.origin, s.direction) : length(q - s.origin);
    float bias = shadow_bias(footprint, max(dot(n, l), 0.0));
    float lit = 0.0;
    [[dont_unroll]] for (int i = 0; i < 16; i++) {
        vec2 t = uv + tap(i, angle) * (1.5 / float(s.resolution));
        ivec2 texel = clamp(ivec2(t * float(s.resolution)), ivec2(0), ivec2(int(s.resolution) - 1));
        float stored = texelFetch(shadow_2d[s.slot], texel, 0).r;
        lit += dq <= stored + bias ? 1.0 : 0.0;
    }
    return lit / 16.0;
}

// Cube map (point and rect lights). Point lights: 16-tap PCF over 1.5 texels. Rect lights: PCSS,
// a blocker search over the light's extent, then PCF over the penumbra it implies.
float shadow_cube_factor(GpuShadow s, vec3 p, vec3 n, vec3 l, float light_radius, float angle) {
    vec3 to = p - s.origin;
    float d = length(to);
    float footprint = d * s.texel;
    vec3 q = p + n * footprint;
    vec3 dir = q - s.origin;
    float dq = length(dir);
    dir /= dq;
    vec3 u = normalize(abs(dir.y) < 0.9 ? cross(dir, vec3(0.0, 1.0, 0.0)) : cross(dir, vec3(1.0, 0.0, 0.0)));
    vec3 w = cross(dir, u);
    float bias = shadow_bias(footprint, max(dot(n, l), 0.0));
    float radius = 1.5 * s.texel;
    if (light_radius > 0.0) {
        // Blocker search: directions within the light's apparent size seen from the receiver.
        float search = light_radius / dq;
        float blockers = 0.0, sum = 0.0;
        [[dont_unroll]] for (int i = 0; i < 16; i++) {
            vec2 t = tap(i, angle) * search;
            float stored = texture(shadow_cube[s.slot], dir + u * t.x + w * t.y).r;
            if (stored + bias < dq) {
                blockers += 1.0;
                sum += stored;
            }
        }
        if (blockers == 0.0) {
            return 1.0;
        }
        float db = sum / blockers;
        float penumbra = light_radius * (dq - db) / max(db, 1e-4);
        radius = max(radius, penumbra / dq);
    }
    float lit = 0.0;
    [[dont_unroll]] for (int i = 0; i < 16; i++) {
        vec2 t = tap(i, angle) * radius;
        float stored = texture(shadow_cube[s.slot], dir + u * t.x + w * t.y).r;
        lit += dq <= stored + bias ? 1.0 : 0.0;
    }
    return lit / 16.0;
}

float shadow_factor(uint index, GpuLight light, vec3 p, vec3 n, vec3 l, float angle) {
    if (DIRECT_RT_SHADOWS && (frame.size.w & FRAME_RT_SHADOWS) != 0u) {
        ivec3 at = ivec3(ivec2(gl_GlobalInvocationID.xy + origin), int(index));
        return index < uint(imageSize(rt_shadows).z) ? imageLoad(rt_shadows, at).r : 1.0;
    }
    if ((frame.size.w & FRAME_SHADOW_MAPS) == 0u || light.shadow < 0) {
        return 1.0;
    }
    GpuShadow s = shadows[light.shadow];
    if (s.projection == SHADOW_CUBE) {
        float radius = DIRECT_RECT_LIGHTS && light.kind == LIGHT_RECT ? 0.5 * length(vec2(light.width, light.height)) : 0.0;
        return shadow_cube_factor(s, p, n, l, radius, angle);
    }
    return shadow_2d_factor(s, p, n, l, angle);
}

// The world position of a pixel's centre at the given (reversed-Z) depth.
vec3 world_at(ivec2 pixel, float depth) {
    return world_at_depth(vec2(pixel) + 0.5, depth);
}

// The ray-traced reflection at a pixel (rgb, a > 0 where traced). Half resolution: the four
// nearest traced pixels (each block's top-left), bilinear weights times how well their surface
// matches this pixel's (normal and plane distance), so that reflections do not bleed across
// edges as plain bilinear upsampling does.
vec4 reflection_at(ivec2 pixel, vec3 p, vec3 n) {
    if ((frame.size.w & FRAME_REFLECTIONS_HALF) == 0u) {
        vec4 r = imageLoad(rt_reflections, pixel);
        return r.a > 0.0 ? vec4(r.rgb, 1.0) : vec4(0.0);
    }
    ivec2 cells = imageSize(rt_reflections);
    vec2 x = vec2(pixel) * 0.5;
    ivec2 c0 = ivec2(floor(x));
    vec2 f = x - vec2(c0);
    float scale = max(length(frame.camera.xyz - p), 1e-6);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int j = 0; j < 2; j++) {
        for (int i = 0; i < 2; i++) {
            ivec2 c = min(c0 + ivec2(i, j), cells - 1);
            ivec2 src = min(c * 2, ivec2(frame.size.xy) - 1);
            float depth = texelFetch(g_depth, src, 0).r;
            if (depth <= 0.0) {
                continue;
            }
            vec3 q = world_at(src, depth);
            vec3 nq = oct_decode(texelFetch(g_normal, src, 0).rg);
            float bilinear = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
            float normal_match = pow(max(dot(nq, n), 0.0), 16.0);
            float plane_match = exp(-abs(dot(q - p, n)) / (0.01 * scale));
            vec4 r = imageLoad(rt_reflections, c);
            float w = (bilinear + 1e-3) * normal_match * plane_match * r.a;
            sum += r.rgb * w;
            weight += w;
        }
    }
    return weight > 1e-6 ? vec4(sum / weight, 1.0) : vec4(0.0);
}

// f · |n·l| of the light arriving along l: reflected above the surface, and below it through a
// thin-walled transmitting surface's mirrored lobe (`transmitted_brdf`; zero for opaque ones).
vec3 f_cos(Material m, vec3 n, vec3 v, vec3 l, float e_albedo) {
    float n_l = dot(n, l);
    if (n_l > 0.0) {
        return brdf(m, n, v, l, e_albedo) * n_l;
    }
    return n_l < 0.0 ? transmitted_brdf(m, n, v, l) * -n_l : vec3(0.0);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy + origin);
    uvec2 size = frame.size.xy;
    if (any(greaterThanEqual(uvec2(pixel), size))) {
        return;
    }
    float depth = texelFetch(g_depth, pixel, 0).r;
    // Rect lights are surfaces the camera sees (as in the path tracer): the nearest in front of
    // the G-buffer's surface shows its radiance. Reversed Z: the far plane (cleared, nothing
    // drawn, the sky) is depth 0.
    // The ray's origin: the eye, or on an orthographic camera the pixel's point on the near plane.
    vec3 eye = camera_orthographic() ? world_at(pixel, 1.0) : frame.camera.xyz;
    vec3 toward = world_at(pixel, depth > 0.0 ? depth : 1e-6) - eye;
    float t_seen = depth > 0.0 ? 1.0 : 3.4e38;
    vec3 seen = env_radiance(normalize(toward), frame.sky.rgb);
    for (uint i = 0u; i < frame.size.z; i++) {
        if (DIRECT_RECT_LIGHTS && lights[i].kind == LIGHT_RECT) {
            float t = rect_light_hit(lights[i], eye, toward, t_seen);
            if (t > 0.0) {
                t_seen = t;
                seen = lights[i].radiance;
            }
        }
    }
    if (depth <= 0.0 || t_seen < 1.0) {
        // Alpha 0 where a rect light hides the surface: over the see-through layer the light is
        // already what the opaque pass shows there (see_through.comp leaves such pixels).
        imageStore(radiance_out, pixel, vec4(seen, depth > 0.0 ? 0.0 : 1.0));
        return;
    }
    vec3 p = world_at(pixel, depth);
    vec3 n = oct_decode(texelFetch(g_normal, pixel, 0).rg);
    vec4 mat = texelFetch(g_material, pixel, 0);
    Material m = gbuffer_material(texelFetch(g_albedo, pixel, 0), mat);
    vec4 emitted = texelFetch(g_emission, pixel, 0);
    vec2 coat = gbuffer_coat_decode(emitted.a);
    m.clearcoat = coat.x;
    m.clearcoat_roughness = coat.y;
    vec3 v = towards_camera(p);
    if (dot(n, v) < 0.0) {
        n = -n;
    }
    float n_v = clamp(dot(n, v), 1e-4, 1.0);
    float lut_res = frame.params.y;
    float e_albedo = m.diffuse_only ? 1.0 : directional_albedo(brdf_lut, lut_res, n_v, m.roughness);
    float angle = 6.2831853 * hash(uvec2(pixel));

    vec3 radiance = emitted.rgb;
    if (DIRECT_EMISSIVE && (frame.size.w & FRAME_RT_DIRECT) != 0u) {
        radiance += imageLoad(rt_direct, pixel).rgb;
    }
    float occlusion = mat.a;
    if (DIRECT_AO && (frame.size.w & FRAME_RT_AO) != 0u) {
        occlusion *= imageLoad(rt_ao, pixel).r;
    }
    vec4 traced = vec4(0.0);
    // Surfaces rougher than the limit keep the split sum, also where half-resolution upsampling
    // would borrow a smoother neighbour's traced reflection.
    if (DIRECT_RT_REFLECTIONS && (frame.size.w & FRAME_RT_REFLECTIONS) != 0u && !m.diffuse_only && m.roughness <= frame.params.w) {
        traced = reflection_at(pixel, p, n);
    }
    // Constant sky: Lambert integrates to base · L_sky; the specular lobe to (F0 R + G) L_sky.
    // An environment: Lambert to base times its irradiance over pi (harmonics), the lobe to
    // (F0 R + G) times its level prefiltered for the roughness around the mirror direction.
    // With GI the diffuse part is the diffuse weight times the traced mean incoming radiance,
    // which holds the sky (its misses), the emissive surfaces and the indirect light, occluded
    // by the scene itself: no AO or occlusion texture multiplies it.
    // Screen-space GI gathers what the screen shows: the sky's ambient (darkened by AO) stays,
    // and the gathered light adds to it.
    bool gi = DIRECT_GI && (frame.size.w & FRAME_RT_GI) != 0u;
    vec3 diffuse_in;
    if (gi) {
        vec4 traced = imageLoad(rt_gi, pixel);
        diffuse_in = traced.rgb;
        // The probes' alpha is their confidence: below 1 past the volume's outermost probes on a
        // side the surface faces out of, where the sky stands in for the missing probes. (The
        // ray-traced GI's alpha is its variance, hence the flag.)
        if (DIRECT_PROBE_SPECULAR && (frame.size.w & FRAME_PROBE_SPECULAR) != 0u && traced.a < 1.0) {
            diffuse_in = mix(env_irradiance(n, frame.sky.rgb) * occlusion, traced.rgb, max(traced.a, 0.0));
        }
    } else {
        diffuse_in = env_irradiance(n, frame.sky.rgb) * occlusion;
    }
    if (DIRECT_GI && (frame.size.w & FRAME_SCREEN_GI) != 0u) {
        diffuse_in += imageLoad(rt_gi, pixel).rgb;
    }
    // The clear coat (KHR_materials_clearcoat) keeps 1 − w of the light the base reflects, and
    // reflects w of the sky's prefiltered light about the mirror direction with its lobe's
    // directional albedo (the split sum's R + G: the coat's Fresnel is in w).
    float coat_w = coat_weight(m.clearcoat, n_v);
    vec3 coat_sky = vec3(0.0);
    if (coat_w > 0.0) {
        vec2 rg = lut_res >= 1.0 ? texture(brdf_lut, vec2(n_v, m.clearcoat_roughness)).rg : vec2(1.0, 0.0);
        coat_sky = coat_w * (rg.r + rg.g) * env_filtered(reflect(-v, n), m.clearcoat_roughness, frame.sky.rgb) * occlusion;
    }
    vec3 ambient = vec3(0.0);
    if (m.diffuse_only) {
        ambient += m.base * diffuse_in;
    } else {
        vec2 rg = lut_res >= 1.0 ? texture(brdf_lut, vec2(n_v, m.roughness)).rg : vec2(1.0, 0.0);
        vec3 f0 = fresnel_f0(m);
        // The split sum's directional albedo of the lobe: F0 R + F90 G.
        vec3 lobe = f0 * rg.r + fresnel_f90(m) * rg.g;
        vec3 compensation = vec3(1.0) + f0 * (1.0 / e_albedo - 1.0);
        vec3 diffuse = (vec3(1.0) - lobe) * (1.0 - m.metallic) * (1.0 - m.transmission) * m.base;
        ambient += diffuse * diffuse_in;
        // The traced reflection estimates the single-scattering lobe; the same multiple-
        // scattering compensation as the split sum applies.
        vec3 mirror = reflect(-v, n);
        vec3 filtered = env_filtered(mirror, m.roughness, frame.sky.rgb);
        vec3 sky_in = filtered * occlusion;
        if (DIRECT_PROBE_SPECULAR && (frame.size.w & FRAME_PROBE_SPECULAR) != 0u) {
            // The probes hold the light that reaches the surface along the mirror direction, the
            // sky's occluded, the room's indirect; as irradiance (a cosine lobe), so the
            // environment's own prefiltered-to-irradiance ratio there gives back its sharpness
            // (1 under the constant sky), bounded where the irradiance is near black. Like the
            // diffuse GI it replaces the material's occlusion: the probes saw the occluders.
            vec4 probe = imageLoad(probe_specular, pixel);
            float ratio = env_sharpness(mirror, filtered, frame.sky.rgb);
            sky_in = mix(sky_in, probe.rgb * ratio, clamp(probe.a, 0.0, 1.0));
        }
        if (DIRECT_SCREEN_REFLECTIONS && (frame.size.w & FRAME_SCREEN_REFLECTIONS) != 0u) {
            // The split sum's prefiltered incoming radiance: what the screen showed along the
            // mirror direction, the sky (occluded) where it showed nothing; the same table weighs
            // both (seed 000 eq. 2.19).
            vec4 screen = imageLoad(rt_reflections, pixel);
            sky_in = mix(sky_in, screen.rgb, clamp(screen.a, 0.0, 1.0));
        }
        vec3 split_sum = lobe * sky_in;
        ambient += compensation * (traced.a > 0.0 ? traced.rgb / traced.a : split_sum);
    }
    radiance += ambient * (1.0 - coat_w) + coat_sky;

    for (uint i = 0u; i < frame.size.z; i++) {
        GpuLight light = lights[i];
        vec3 contribution = vec3(0.0);
        vec3 shadow_dir;
        if (light.kind == LIGHT_DIRECTIONAL) {
            vec3 l = -light.direction;
            shadow_dir = l;
            contribution = f_cos(m, n, v, l, e_albedo) * light.radiance;
        } else if (DIRECT_RECT_LIGHTS && light.kind == LIGHT_RECT) {
            vec3 up = cross(light.direction, light.right);
            float area = light.width * light.height;
            shadow_dir = normalize(light.position - p);
            for (int a = 0; a < 4; a++) {
                for (int b = 0; b < 4; b++) {
                    vec3 q = light.position + light.right * ((float(a) + 0.5) / 4.0 - 0.5) * light.width
                        + up * ((float(b) + 0.5) / 4.0 - 0.5) * light.height;
                    vec3 to = q - p;
                    float d = length(to);
                    if (d <= 0.0 || (light.range > 0.0 && d > light.range)) {
                        continue;
                    }
                    vec3 l = to / d;
                    float cos_light = dot(-l, light.direction);
                    if (cos_light <= 0.0) {
                        continue;
                    }
                    contribution += f_cos(m, n, v, l, e_albedo) * light.radiance * (cos_light * area / (16.0 * d * d));
                }
            }
        } else {
            vec3 to = light.position - p;
            float d = length(to);
            vec3 l = to / max(d, 1e-12);
            shadow_dir = l;
            if (d > 0.0 && (light.range <= 0.0 || d <= light.range)) {
                float cone = 1.0;
                if (light.kind == LIGHT_SPOT) {
                    cone = spot_cone(light, l);
                }
                contribution = f_cos(m, n, v, l, e_albedo) * light.radiance * (cone / (d * d));
            }
        }
        if (any(greaterThan(contribution, vec3(0.0)))) {
            // Light through a transmitting surface is shadowed from its far side.
            bool behind = m.transmission > 0.0 && dot(n, shadow_dir) < 0.0;
            contribution *= shadow_factor(i, light, p, behind ? -n : n, shadow_dir, angle);
            // Light through participating media arrives dimmed (towards the light's position,
            // a rect light's centre; out of every box for directional lights).
            uint media_count = uint(frame.sky.w);
            if (DIRECT_MEDIA && media_count > 0u) {
                float reach = light.kind == LIGHT_DIRECTIONAL ? 3.4e38 : length(light.position - p);
                contribution *= exp(-optical_depth(media_count, p, shadow_dir, 0.0, reach));
            }
        }
        radiance += contribution;
    }
    imageStore(radiance_out, pixel, vec4(radiance, 1.0));
}
