#version 460
#extension GL_EXT_control_flow_attributes : require
// Temporal anti-aliasing (`--aa taa`, seed 000 §3.10, after Karis 2014): this frame's jittered
// radiance blended into the history reprojected from the previous camera.
//
// - Reprojection (common/reproject.glsl): the pixel's surface point through `frame.reproject`
//   into the previous frame's unjittered image, less this frame's jitter (the sample lies at
//   the pixel centre + jitter, the history at pixel centres); read there through a Catmull–Rom
//   filter. A still camera reads the pixel's own history texel.
// - Clip: the history is clipped towards the centre of this frame's 3 × 3 neighbourhood's box
//   in YCoCg (min/max, narrowed to mean ± σ): whatever the history shows that the neighbourhood
//   does not (a surface disoccluded since) is pulled onto it, which removes ghosts. A depth
//   test for disocclusion (the previous frame's depth at the reprojected point) was tried and
//   left out: the jitter moves edge pixels' samples between the surfaces on either side, so it
//   restarts the history along every moving edge (mean FLIP at edges 0.135 with it, 0.079
//   without, one sample 0.099, on the moving-strips test).
// - Blend: a new sample weighs 1 / min(n + 1, frames) after n frames of history (stored in the
//   history's alpha): the running mean until `frames`, an exponential mean after (the seed's
//   0.88–0.97 is frames 8–33). With luma weights each colour is blended as c / (1 + luma)
//   and turned back by c / (1 − luma) (the seed's, Karis's: damps fireflies); luma with the
//   shaders' 0.299 (the seed's text prints 0.229, a typo).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D current;
layout(set = 0, binding = 2) uniform sampler2D history;
layout(set = 0, binding = 3) uniform sampler2D depth;
// Half floats: the history is read five times per pixel (Catmull–Rom) and written once; half the
// bytes of 32-bit floats, and 2^-11 relative precision, below what a frame's blend changes.
layout(set = 0, binding = 4, rgba16f) uniform writeonly image2D resolved;
layout(push_constant) uniform Push {
    float frames;       // the longest history
    uint luma_weights;  // 1: blend c / (1 + luma)
} taa;

#include "../common/reproject.glsl"
#include "../common/random.glsl"

float luma(vec3 c) {
    return sqrt(max(0.299 * c.r * c.r + 0.587 * c.g * c.g + 0.114 * c.b * c.b, 0.0));
}

// Radiance to the space it is blended in (and back).
vec3 weigh(vec3 c) {
    return taa.luma_weights != 0u ? c / (1.0 + luma(c)) : c;
}

vec3 unweigh(vec3 c) {
    // luma(c / (1 + L)) = L / (1 + L) < 1: the inverse is finite.
    return taa.luma_weights != 0u ? c / max(1.0 - luma(c), 1e-6) : c;
}

vec3 to_ycocg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}

vec3 from_ycocg(vec3 c) {
    return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

// The history at image point `at` (pixels) through a Catmull–Rom filter: bilinear reads,
// resampled every frame, would blur the history a little more each frame the camera moves.
// Five bilinear taps (the 4 × 4 kernel's corners dropped, their weight renormalised); at a
// texel centre it returns that texel exactly. Alpha (the history length) from the middle tap: a
// bilinear read of the 2 × 2 texels nearest the point.
vec4 history_at(vec2 at) {
    vec2 size = vec2(textureSize(history, 0));
    vec2 centre = floor(at - 0.5) + 0.5;
    vec2 f = at - centre;
    vec2 w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
    vec2 w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
    vec2 w2 = f * (0.5 + f * (2.0 - 1.5 * f));
    vec2 w3 = f * f * (-0.5 + 0.5 * f);
    vec2 w12 = w1 + w2;
    vec2 t0 = (centre - 1.0) / size;
    vec2 t3 = (centre + 2.0) / size;
    vec2 t12 = (centre + w2 / w12) / size;
    vec4 middle = textureLod(history, t12, 0.0);
    vec3 c = textureLod(history, vec2(t12.x, t0.y), 0.0).rgb * (w12.x * w0.y)
           + textureLod(history, vec2(t0.x, t12.y), 0.0).rgb * (w0.x * w12.y)
           + middle.rgb * (w12.x * w12.y)
           + textureLod(history, vec2(t3.x, t12.y), 0.0).rgb * (w3.x * w12.y)
           + textureLod(history, vec2(t12.x, t3.y), 0.0).rgb * (w12.x * w3.y);
    float total = w12.x * w0.y + w0.x * w12.y + w12.x * w12.y + w3.x * w12.y + w12.x * w3.y;
    return vec4(max(c / total, vec3(0.0)), middle.a);
}

// `c` moved along the line to the box's centre until it lies in the box (Playdead's clip: a
// hue the box lacks is not kept by clamping each channel separately).
vec3 clip_to_box(vec3 c, vec3 lo, vec3 hi) {
    vec3 mid = 0.5 * (hi + lo);
    vec3 half_size = max(0.5 * (hi - lo), vec3(1e-7));
    vec3 d = (c - mid) / half_size;
    float reach = max(abs(d.x), max(abs(d.y), abs(d.z)));
    return reach > 1.0 ? mid + (c - mid) / reach : c;
}

// This workgroup's 8 × 8 pixels and a one-pixel border: each pixel's weighted YCoCg colour and
// depth, loaded once into shared memory (the 3 × 3 neighbourhoods overlap nine-fold).
shared vec3 tile_colour[10][10];
shared float tile_depth[10][10];

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(frame.size.xy);
    ivec2 origin = ivec2(gl_WorkGroupID.xy) * 8 - 1;
    for (uint i = gl_LocalInvocationIndex; i < 100u; i += 64u) {
        ivec2 t = ivec2(i % 10u, i / 10u);
        ivec2 q = clamp(origin + t, ivec2(0), size - 1);
        tile_colour[t.y][t.x] = to_ycocg(weigh(imageLoad(current, q).rgb));
        tile_depth[t.y][t.x] = texelFetch(depth, q, 0).r;
    }
    barrier();
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    ivec2 local = ivec2(gl_LocalInvocationID.xy) + 1;
    vec3 centre = from_ycocg(tile_colour[local.y][local.x]);
    vec3 lo = tile_colour[local.y][local.x], hi = lo;
    vec3 sum = vec3(0.0), sum2 = vec3(0.0);
    float nearest = 0.0;
    [[unroll]] for (int dy = -1; dy <= 1; ++dy) {
        [[unroll]] for (int dx = -1; dx <= 1; ++dx) {
            vec3 c = tile_colour[local.y + dy][local.x + dx];
            lo = min(lo, c);
            hi = max(hi, c);
            sum += c;
            sum2 += c * c;
            // Reversed Z: the nearest surface has the largest depth.
            nearest = max(nearest, tile_depth[local.y + dy][local.x + dx]);
        }
    }
    // Variance clipping (Salvi 2016) inside the min/max box: the box of mean ± σ, tighter where
    // one bright outlier (a thin edge) would stretch the min/max box over everything between.
    vec3 mean = sum / 9.0;
    vec3 sigma = sqrt(max(sum2 / 9.0 - mean * mean, vec3(0.0)));
    lo = max(lo, mean - sigma);
    hi = min(hi, mean + sigma);
    vec2 at;
    float depth_then;
    // The nearest depth of the neighbourhood moves the pixel with the nearest surface in it: the
    // few pixels around a foreground edge move with the edge, so its anti-aliased profile
    // travels with it instead of trailing behind (Karis 2014).
    bool valid = reproject_pixel(pixel, nearest, at, depth_then);
    vec3 blended = centre;
    float n = 0.0;
    if (valid) {
        vec4 h = history_at(at);
        vec3 clamped = from_ycocg(clip_to_box(to_ycocg(weigh(h.rgb)), lo, hi));
        n = h.a;
        float w = 1.0 / min(n + 1.0, taa.frames);
        blended = mix(clamped, centre, w);
    }
    // Half floats round a blend's small steps away (a step below half a unit in the last place is
    // lost every frame, so the mean stalls short of its value); a random offset of up to half a
    // unit in the last place makes the rounding right on average.
    vec3 result = min(unweigh(blended), vec3(65000.0));
    uint h = hash(uint(pixel.x) * 1973u + uint(pixel.y) * 9277u + uint(frame.params.z) * 26699u);
    vec3 ulp = exp2(floor(log2(max(result, vec3(6.1e-5)))) - 10.0);
    result = max(result + ulp * (float(h & 0xffffu) / 65536.0 - 0.5), vec3(0.0));
    imageStore(resolved, pixel, vec4(result, min(n + 1.0, 65000.0)));
}
