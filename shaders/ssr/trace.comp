#version 460
// Screen-space reflections by hierarchical depth tracing (Hi-Z: Uludag 2014 after McGuire & Mara
// 2014; AMD FidelityFX SSSR). Per pixel: the view ray mirrored about the normal is marched through
// the Hi-Z pyramid (shaders/hiz/: each cell the closest depth below it) as a straight line in
// (image x, image y, reversed-Z depth), which a perspective ray is. In front of a cell's closest
// surface the ray skips to the cell's wall and climbs a level (empty space); where it reaches that
// depth inside the cell it steps down a level (a potential hit), until a hit at a level whose cells
// fit in the reflection cone's footprint: level 0 for a mirror, coarser for rough surfaces (seed
// 000 §3.9/§10: cone half-angle θ = acos(0.244^(1/(power + 1)))/2, power = clamp(2/max(1e-4, r²)
// − 2, 4, 16384) for roughness r). The hit shows the previous frame's lit radiance, reprojected
// (shaders/lit/), at the level of that pyramid the cone's footprint at the hit covers (seed 000
// §10: log₂ of the footprint in pixels).
// Output: rgb the incoming radiance along the mirror direction, a the confidence in it (0 where
// the ray misses, leaves the image or the surface is too rough; faded near the image's edges):
// the direct pass makes up the rest with the split-sum ambient.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D g_depth;
layout(set = 0, binding = 2) uniform sampler2D g_normal;
layout(set = 0, binding = 3) uniform sampler2D g_material;
layout(set = 0, binding = 4, r32f) uniform readonly image2D hiz;
// The lit pyramid: the previous frame's radiance in this frame's pixels (alpha the lit fraction).
layout(set = 0, binding = 5, rgba16f) uniform readonly image2D lit;
layout(set = 0, binding = 6, rgba32f) uniform writeonly image2D reflections;
layout(push_constant) uniform Push { SsrConstants ssr; };

#include "../common/packing.glsl"
#include "../common/screen_ao.glsl"

// The most Hi-Z levels (player/src/render/passes/hiz.rs: TOP + 1).
const int MAX_LEVELS = 9;
// The coarsest level a rough ray may hit at: coarser cells hold too many surfaces to stand for one.
const int MAX_HIT_LEVEL = 4;
// How far past a cell's wall a step lands (pixels): inside the next cell despite rounding.
const float CROSS = 0.01;
// The border, as a fraction of the image's width and height, over which hits fade out: the
// image ends there, and what lies beyond it (which the split sum stands in for) should not start
// at a visible seam.
const float EDGE_FADE = 0.05;
const float FAR = 3.4e38;

ivec2 origins[MAX_LEVELS];

// Image point (pixels) and reversed-Z depth of world point w.
vec3 to_image(vec3 w) {
    vec4 c = frame.view_proj * vec4(w, 1.0);
    return vec3(ndc_to_image(c.xy / c.w), c.z / c.w);
}

// sin θ / (1 + sin θ) for the cone of roughness r (seed 000 §10): the inradius of the cone's
// isosceles cross-section per unit of its length (HFK16), so that the footprint's diameter at
// distance L is 2 L times this.
float cone_inradius(float r) {
    float power = clamp(2.0 / max(1e-4, r * r) - 2.0, 4.0, 16384.0);
    float theta = 0.5 * acos(pow(0.244, 1.0 / (power + 1.0)));
    float s = sin(theta);
    return s / (1.0 + s);
}

// The parameter t (pixels along the image) at which the ray s0 + d t leaves the image or the
// depth range (0: infinitely far or the far plane; 1: the near plane).
float exit_distance(vec3 s0, vec3 d) {
    vec3 lo = vec3(0.0), hi = vec3(vec2(frame.size.xy), 1.0);
    vec3 wall = mix(lo, hi, greaterThan(d, vec3(0.0)));
    vec3 t = mix(vec3(FAR), (wall - s0) / d, notEqual(d, vec3(0.0)));
    return min(t.x, min(t.y, t.z));
}

// The lit pyramid's level `level` at image point `at` (pixels of level 0), bilinear over the
// level's lit texels; alpha the lit fraction (0 on the sky and where there is no history).
vec4 lit_at_level(vec2 at, int level) {
    ivec2 size = pyramid_size(level);
    vec2 x = at / float(1 << level) - 0.5;
    ivec2 base = ivec2(floor(x));
    vec2 f = x - vec2(base);
    vec4 sum = vec4(0.0);
    for (int i = 0; i < 4; i++) {
        ivec2 o = ivec2(i & 1, i >> 1);
        float w = (o.x == 0 ? 1.0 - f.x : f.x) * (o.y == 0 ? 1.0 - f.y : f.y);
        vec4 l = imageLoad(lit, origins[level] + clamp(base + o, ivec2(0), size - 1));
        sum += w * vec4(l.rgb * l.a, l.a);
    }
    return sum.a > 0.0 ? vec4(sum.rgb / sum.a, sum.a) : vec4(0.0);
}

// The lit radiance at image point `at` over a footprint `level` levels wide (fractional: the two
// levels around it, blended).
vec4 lit_radiance(vec2 at, float level) {
    level = clamp(level, 0.0, float(PYRAMID_TOP));
    int lo = int(floor(level));
    int hi = min(lo + 1, PYRAMID_TOP);
    return mix(lit_at_level(at, lo), lit_at_level(at, hi), level - float(lo));
}

vec4 reflection(ivec2 p) {
    // A frame without history finds no lit texel at first (alpha 0): it runs again once the
    // pyramid holds its own radiance (player/src/render/frame.rs, `again`).
    float depth = texelFetch(g_depth, p, 0).r;
    vec4 mat = texelFetch(g_material, p, 0);
    float roughness = mat.g;
    if (!(depth > 0.0) || gbuffer_diffuse_only(mat) || roughness > ssr.max_roughness) {
        return vec4(0.0);
    }
    vec2 at = vec2(p) + 0.5;
    vec3 pos = world_at_depth(at, depth);
    vec3 n = oct_decode(texelFetch(g_normal, p, 0).rg);
    vec3 v = towards_camera(pos);
    if (dot(n, v) < 0.0) {
        n = -n;
    }
    vec3 r = reflect(-v, n);
    // Start a pixel's footprint off the surface, so that the march does not find the surface it
    // leaves in the pixels next to its own (their depth is taken at their centres).
    vec3 start = pos + n / pixels_per_unit(camera_depth(at, depth));
    vec4 c0 = frame.view_proj * vec4(start, 1.0);
    float dw = (frame.view_proj * vec4(r, 0.0)).w;
    // A second point along the ray still in front of the camera (clip w > 0; a ray towards the
    // camera: where it is half as far): the ray is the straight image-space line through both.
    float len = dw < 0.0 ? 0.5 * c0.w / -dw : max(c0.w, 1.0);
    vec3 s0 = to_image(start);
    vec3 d = to_image(start + r * len) - s0;
    float extent = length(d.xy);
    if (extent < 1e-4) {
        // Straight along the view ray: nothing to march across.
        return vec4(0.0);
    }
    d /= extent;
    float t_max = exit_distance(s0, d);
    vec2 dxy = mix(d.xy, vec2(1e-12), lessThan(abs(d.xy), vec2(1e-12)));
    vec2 heading = step(0.0, dxy);

    int top = min(int(ssr.top), MAX_LEVELS - 1);
    for (int l = 0; l <= max(top, PYRAMID_TOP); l++) {
        origins[l] = pyramid_origin(l);
    }
    float k = cone_inradius(roughness);
    int hit_cap = min(top, MAX_HIT_LEVEL);
    // Leave the start's own pixel first.
    vec2 wall = (floor(s0.xy) + heading - s0.xy) / dxy;
    float t = min(wall.x, wall.y) + CROSS;
    int level = 0;
    bool hit = false;
    for (uint i = 0u; i < ssr.steps && t < t_max; i++) {
        vec3 s = s0 + d * t;
        // The coarsest level whose cells fit in the cone's footprint this far along.
        int accept = min(int(floor(log2(max(2.0 * k * t, 1.0)))), hit_cap);
        float size = float(1 << level);
        vec2 cell = floor(s.xy / size);
        float closest = imageLoad(hiz, origins[level] + ivec2(cell)).r;
        vec2 to_wall = ((cell + heading) * size - s0.xy) / dxy;
        float t_exit = min(to_wall.x, to_wall.y);
        if (s.z > closest) {
            // In front of everything in the cell: where does the ray reach its closest depth?
            float t_cross = d.z < 0.0 ? (closest - s0.z) / d.z : FAR;
            if (t_cross < t_exit) {
                t = max(t, t_cross);
                if (level <= accept) {
                    hit = true;
                    break;
                }
                level--;
            } else {
                t = t_exit + CROSS;
                level = min(level + 1, top);
            }
        } else if (level <= accept) {
            // Entered the cell behind its closest surface: a hit if no further behind it than the
            // thickness (a wall met edge-on), else the ray passes behind it.
            float z_surface = camera_depth(s.xy, closest);
            if (camera_depth(s.xy, s.z) - z_surface <= ssr.thickness * z_surface) {
                hit = true;
                break;
            }
            t = t_exit + CROSS;
        } else {
            level--;
        }
    }
    if (!hit) {
        return vec4(0.0);
    }
    vec3 s = s0 + d * t;
    ivec2 h = clamp(ivec2(floor(s.xy)), ivec2(0), ivec2(frame.size.xy) - 1);
    vec2 h_at = vec2(h) + 0.5;
    float h_depth = texelFetch(g_depth, h, 0).r;
    if (!(h_depth > 0.0)) {
        return vec4(0.0);
    }
    vec3 q = world_at_depth(h_at, h_depth);
    vec3 nq = oct_decode(texelFetch(g_normal, h, 0).rg);
    if (dot(nq, towards_camera(q)) < 0.0) {
        nq = -nq;
    }
    // The ray must meet the side the camera sees (the other side's radiance is not on screen).
    if (dot(nq, r) >= 0.0) {
        return vec4(0.0);
    }
    // The cone's footprint at the hit (its diameter in pixels there) picks the level.
    float footprint = 2.0 * k * distance(pos, q) * pixels_per_unit(camera_depth(h_at, h_depth));
    vec4 radiance = lit_radiance(s.xy, log2(max(footprint, 1.0)));
    vec2 size = vec2(frame.size.xy);
    vec2 border = min(s.xy, size - s.xy) / size;
    float confidence = radiance.a * smoothstep(0.0, EDGE_FADE, min(border.x, border.y));
    // Fade out over the last fifth below the roughness limit rather than stop at a visible edge.
    confidence *= clamp((ssr.max_roughness - roughness + 1e-4) / max(0.2 * ssr.max_roughness, 1e-4), 0.0, 1.0);
    if (any(isnan(radiance.rgb)) || any(isinf(radiance.rgb))) {
        return vec4(0.0);
    }
    return vec4(radiance.rgb, confidence);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), frame.size.xy))) {
        return;
    }
    imageStore(reflections, p, reflection(p));
}
