// The spatiotemporal denoiser (`--denoise svgf`; Schied et al., "Spatiotemporal
// Variance-Guided Filtering", HPG 2017), over the running means the ray-traced passes already
// keep: their temporal accumulation (a still camera's running mean, or the reprojected history
// of `--aa reproject|taa`) is the temporal filter, and it stays unfiltered, so that a still
// image converges to the same mean as without the denoiser. One or two signals at once (image
// arrays of two, each tap's geometry weighed once for both). Per frame:
// 1. guide.comp: each pixel's distance along its camera ray and its normal, read by every tap;
// 2. variance.comp: each signal divided by the albedo's demodulator where it carries the albedo,
//    and the standard deviation of its running mean (half floats from here on): from the second
//    moment (alpha) over the samples averaged, or, with fewer than 4 samples, from the 5 × 5
//    neighbours on the same surface;
// 3. atrous.glsl (atrous.comp 5 × 5 B3-spline taps, atrous3.comp 3 × 3), per iteration i: taps
//    2^i pixels apart, each weighted by its distance from the pixel's tangent plane, the
//    normals' agreement and the luminance difference in standard deviations of the noise; the
//    variance filtered with the squared weights (kept as its square root, for half floats'
//    range); the last iteration multiplies the demodulator back and writes the image the
//    composition reads.
// As the samples grow the variance of the mean falls as 1/n and the luminance weight closes:
// the filter fades into the identity.
#include "../common/layout.glsl"
#include "../common/packing.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(push_constant) uniform Push { DenoiseConstants push; };

#include "../common/pixel.glsl"

// The guide of a pixel: its distance along the camera ray through its centre (the ray
// pixel_ray(), not normalised, from pixel_origin()) and its packed normal; a pixel that shows
// the sky (no surface) has a NaN's bits as its distance, which no surface has. 8 bytes a tap:
// positions are rebuilt from the pixel's ray.
const uint GUIDE_SKY = 0x7FC00000u;

struct Guide {
    vec3 p;      // position relative to frame.camera.xyz
    vec3 n;      // shading normal
    bool surface;
};

Guide unpack_guide(ivec2 pixel, uvec2 g) {
    Guide o;
    o.surface = g.x != GUIDE_SKY;
    vec2 at = vec2(pixel) + 0.5;
    o.p = (pixel_origin(at) - frame.camera.xyz) + pixel_ray(at) * uintBitsToFloat(g.x);
    o.n = oct_decode(unpackSnorm2x16(g.y));
    return o;
}

// What signal i is divided by at a surface of sRGB base colour `base`: the albedo's demodulator
// where `push.demodulate` has bit i (the signal carries the albedo), else 1.
vec3 signal_demodulator(uint i, vec3 base) {
    return (push.demodulate & (1u << i)) != 0u ? demodulator(srgb_to_linear(base)) : vec3(1.0);
}

// What the filter's half-float images keep of a value: at most the largest half (radiance
// beyond 65504 is clipped there while filtering; the running means keep full floats).
vec4 half_range(vec4 v) {
    return min(v, vec4(65504.0));
}

// The side of a pixel's footprint at camera-relative point p (world units).
float footprint(vec3 p) {
    float per_unit = 2.0 * frame.camera_up.w / float(frame.size.y);
    return camera_orthographic() ? per_unit : per_unit * length(p);
}

// The edge-stopping weight of geometry between pixel p and a tap q: the tap's distance from
// p's tangent plane against `scale` (σ_plane pixel footprints at p, whatever the taps'
// separation: a surface one unit behind another is as far from it 16 pixels away as 1), and
// the normals' agreement to the power σ_n.
float geometry_weight(Guide p, Guide q, float scale) {
    float plane = abs(dot(p.n, q.p - p.p));
    float wn = pow(max(dot(p.n, q.n), 0.0), push.sigma_normal);
    return exp(-plane / max(scale, 1e-30)) * wn;
}
