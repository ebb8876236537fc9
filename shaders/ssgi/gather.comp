#version 460
// Screen-space diffuse GI (seed 000 §2.1, §3.6), one level of the hierarchy: each texel of level
// `level` gathers `samples` points of the lit-radiance pyramid on a 19-turn spiral around it,
// on the ring between R/2 and R texels (between 1 and R on the finest level, `base`), and adds
// the joint-bilateral upsampling of the coarser level's result (none above `top`). Coarse levels
// thus carry the far light, blurred, and fine ones the near light: each level's ring is the next
// finer level's ring doubled, so the rings tile the screen around the pixel.
//
// Each sample is a small emitter of its lit radiance L (eq. 2.13):
//   L · cos⁺θ · cos⁺θ' · ds / (‖x − y‖² + 0.1) · (area of screen the sample stands for),
// ds the world area of one full-resolution pixel at the sample (z² · pixel solid angle at unit
// depth · cos α / cos β, clamped as the seed does), v = 1 (no visibility, the seed's choice),
// optionally the seed's fall-off (r² → r^2.5 beyond one unit) in its place. Unlike the seed,
// which weighs every sample alike and rescales levels by a hand-tuned exponent (its
// "prioritise near samples" 0.6), each sample weighs the screen area it stands for: with radii
// spread evenly over [r₀, R], 2π r (R − r₀) / N texels of the level, 4^level full-resolution
// pixels each — the Monte Carlo estimate of the on-screen integral. The sum is irradiance; the
// texel stores it. The finest ring starts 1 texel out, not the seed's 4: the 0.1 term already
// bounds the singularity, and the 4-texel hole left out a quarter of the light a floor receives
// within half a unit of a glowing wall (tests/render/ssgi.rs: 0.71 of the closed form, 0.95
// with 1).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, r32f) uniform readonly image2D pyramid;
layout(set = 0, binding = 2, rg16f) uniform readonly image2D normal_pyramid;
layout(set = 0, binding = 3, rgba32ui) uniform readonly uimage2D packed;  // pack.comp, packed.glsl
layout(set = 0, binding = 4, rgba16f) uniform image2D gi_levels;
layout(push_constant) uniform Push { ScreenGiConstants gi; };

#include "../common/screen_ao.glsl"
#include "../common/random.glsl"
#include "upsample.glsl"

const float PI = 3.14159265358979;
const float TURNS = 19.0;
// The seed's singularity term (eq. 2.12), in squared scene units.
const float SINGULARITY = 0.1;

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    int level = int(gi.level);
    ivec2 size = pyramid_size(level);
    if (any(greaterThanEqual(q, size))) {
        return;
    }
    ivec2 origin = pyramid_origin(level);
    float z = imageLoad(pyramid, origin + q).r;
    if (z <= 0.0) {
        imageStore(gi_levels, origin + q, vec4(0.0));
        return;
    }
    vec2 n_enc = imageLoad(normal_pyramid, origin + q).rg;
    vec3 n = oct_decode(n_enc);
    // Points relative to the camera (packed.glsl).
    vec3 x = level_point(q, level, z) - frame.camera.xyz;
    // Light from the side the camera sees.
    if (dot(n, towards_camera(x + frame.camera.xyz)) < 0.0) {
        n = -n;
    }
    vec3 result = level < int(gi.top) ? upsample(q, level, level + 1, z, x, n_enc, true) : vec3(0.0);

    bool finest = level == int(gi.base);
    float r0 = finest ? 1.0 : 0.5 * gi.radius;
    float r1 = max(gi.radius, r0);
    float count = float(max(gi.samples, 1u));
    // Screen area per unit of radius, in full-resolution pixels (see the header).
    float area = 2.0 * PI * (r1 - r0) / count * float(1 << (2 * level));
    // The spiral's rotation: random per texel (the seed's), or per 8 × 8 block (gi.tiled), each
    // frame anew.
    uvec2 key = gi.tiled != 0u ? gl_WorkGroupID.xy : uvec2(q);
    rng = hash(hash(key.x + 0x9e3779b9u * key.y) ^ gi.seed ^ uint(level) * 0x85ebca6bu);
    float angle0 = 2.0 * PI * rnd();
    // The spiral's direction turns by a fixed angle per sample: rotated, not recomputed.
    float step = 2.0 * PI * TURNS / count;
    mat2 turn = mat2(cos(step), sin(step), -sin(step), cos(step));
    vec2 along = vec2(cos(angle0 + 0.5 * step), sin(angle0 + 0.5 * step));
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < gi.samples; i++, along = turn * along) {
        float r = mix(r0, r1, (float(i) + 0.5) / count);
        ivec2 s = ivec2(floor(vec2(q) + 0.5 + r * along));
        if (any(lessThan(s, ivec2(0))) || any(greaterThanEqual(s, size))) {
            continue;
        }
        uvec4 texel = imageLoad(packed, origin + s);
        vec3 y = packed_point(texel);
        vec3 light = packed_light(texel);
        if (!packed_surface(y) || all(equal(light, vec3(0.0)))) {
            continue;
        }
        vec3 ns = oct_decode(packed_normal(texel));
        vec3 diff = x - y;
        float r2 = dot(diff, diff);
        if (r2 <= 0.0) {
            continue;
        }
        vec3 dir = diff * inversesqrt(r2);
        if (gi.falloff != 0u) {
            r2 = mix(r2, pow(r2, 1.25), clamp((r2 - 1.0) * 0.5, 0.0, 1.0));
        }
        // The normal on the side the camera sees.
        if (dot(ns, y) > 0.0) {
            ns = -ns;
        }
        float cos_source = max(dot(ns, dir), 0.0);
        float cos_receiver = max(dot(n, -dir), 0.0);
        // World size of a full-resolution pixel at the sample's camera depth.
        float unit = units_per_pixel(dot(y, frame.camera_forward.xyz));
        float ds = unit * unit * packed_tilt(texel);
        sum += light * (cos_source * cos_receiver * ds / (r2 + SINGULARITY) * r);
    }
    result += sum * area;
    imageStore(gi_levels, origin + q, vec4(min(result, vec3(65000.0)), 1.0));
}
