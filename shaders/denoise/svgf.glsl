// The spatiotemporal denoiser (`--denoise svgf`; Schied et al., "Spatiotemporal
// Variance-Guided Filtering", HPG 2017), over the running means the ray-traced passes already
// keep: their temporal accumulation (a still camera's running mean, or the reprojected history
// of `--aa reproject|taa`) is the temporal filter, and it stays unfiltered, so that a still
// image converges to the same mean as without the denoiser. Per frame:
// 1. guide.comp: each pixel's camera-relative position and normal, read by every tap;
// 2. variance.comp, per signal: the signal divided by the albedo's demodulator where it carries
//    the albedo, and the variance of its running mean: the second moment's (alpha) variance
//    over the samples averaged, or, with fewer than 4 samples, the variance of the 5 × 5
//    neighbours on the same surface;
// 3. atrous.comp, per signal and iteration: the à-trous wavelet filter (5 × 5 B3-spline taps
//    2^i pixels apart), each tap weighted by the distance from the pixel's tangent plane, the
//    normals' agreement and the luminance difference in standard deviations of the noise; the
//    variance filtered with the squared weights; the last iteration multiplies the demodulator
//    back and writes the image the composition reads.
// As the samples grow the variance of the mean falls as 1/n and the luminance weight closes:
// the filter fades into the identity.
#include "../common/layout.glsl"
#include "../common/packing.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(push_constant) uniform Push { DenoiseConstants push; };

#include "../common/pixel.glsl"

// The guide of a pixel that shows the sky (no surface): a NaN's bits, which no stored position
// has.
const uint GUIDE_SKY = 0x7FC00000u;

struct Guide {
    vec3 p;      // position relative to the camera
    vec3 n;      // shading normal
    bool surface;
};

Guide unpack_guide(uvec4 g) {
    Guide o;
    o.surface = g.x != GUIDE_SKY;
    o.p = uintBitsToFloat(g.xyz);
    o.n = oct_decode(unpackSnorm2x16(g.w));
    return o;
}

// The side of a pixel's footprint at camera-relative point p (world units).
float footprint(vec3 p) {
    float per_unit = 2.0 * frame.camera_up.w / float(frame.size.y);
    return camera_orthographic() ? per_unit : per_unit * length(p);
}

// The edge-stopping weight of geometry between pixel p and a tap q `pixels` away: the tap's
// distance from p's tangent plane against σ_plane footprints per pixel of separation, and the
// normals' agreement to the power σ_n.
float geometry_weight(Guide p, Guide q, float pixels) {
    float plane = abs(dot(p.n, q.p - p.p));
    float scale = push.sigma_plane * footprint(p.p) * pixels;
    float wz = exp(-plane / max(scale, 1e-30));
    float wn = pow(max(dot(p.n, q.n), 0.0), push.sigma_normal);
    return wz * wn;
}
