#version 460
// Ground-truth ambient occlusion (Jimenez et al. 2016): the cosine-weighted visibility of the
// hemisphere around the normal, as an integral over `count` slices (half-planes of screen
// directions φ, rotated per pixel) of the visible arc between two horizons. In a slice spanned
// by the view vector V and its screen direction T, a direction is D(h) = V cos h + T sin h; the
// normal projected into the slice has length |n_p| and angle γ from V. Each side takes `steps`
// samples of the depth pyramid's level 0 out to the world radius R projected (quadratically
// spaced, jittered per pixel); a sample within distance R raises that side's horizon h to its
// angle from V. With the horizons clamped to the normal's hemisphere (γ ± π/2) the slice's
// visibility is the exact integral of cos(h − γ)|sin h| between them,
//   â = ¼(−cos(2h₁ − γ) + cos γ + 2h₁ sin γ) + ¼(−cos(2h₂ − γ) + cos γ + 2h₂ sin γ),
// and the pixel's visibility the mean of |n_p| â over the slices (1: nothing occludes).
// Samples beyond R are ignored (a hard radius). Writes (visibility, camera depth) for the blur.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D g_normal;
layout(set = 0, binding = 2, r32f) uniform readonly image2D pyramid;
layout(set = 0, binding = 3, rg32f) uniform writeonly image2D raw;
layout(push_constant) uniform Push { ScreenAoConstants ao; };

#include "../common/packing.glsl"
#include "../common/screen_ao.glsl"

const float PI = 3.14159265358979;
// Samples nearer than this many pixels would land on the centre pixel (XeGTAO's 1.3).
const float TOO_CLOSE = 1.3;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), frame.size.xy))) {
        return;
    }
    float zc = imageLoad(pyramid, p).r;
    if (zc <= 0.0) {
        imageStore(raw, p, vec4(1.0, 0.0, 0.0, 0.0));
        return;
    }
    vec3 centre = point_at_depth(p, zc);
    vec3 v = towards_camera(centre);
    vec3 n = oct_decode(texelFetch(g_normal, p, 0).rg);
    float r_px = ao.radius * pixels_per_unit(zc);
    float slice_jitter = pixel_rotation(p);
    // The same 16 values in another order (5 is prime to 16).
    float step_jitter = fract(slice_jitter * 5.0);
    float min_t = min(TOO_CLOSE / r_px, 1.0);
    float visibility = 0.0;
    for (uint s = 0u; s < ao.count; s++) {
        float phi = (float(s) + slice_jitter) / float(ao.count) * PI;
        vec2 omega = vec2(cos(phi), sin(phi));
        // Screen y runs down, the camera's up vector up.
        vec3 dir = frame.camera_right.xyz * omega.x - frame.camera_up.xyz * omega.y;
        vec3 t = normalize(dir - dot(dir, v) * v);
        vec3 axis = cross(t, v);
        vec3 np = n - axis * dot(n, axis);
        float np_len = length(np);
        if (np_len < 1e-6) {
            continue;
        }
        float gamma = atan(dot(np, t), dot(np, v));
        float arc = 0.0;
        for (int side = -1; side <= 1; side += 2) {
            // The lowest horizon: the normal's tangent plane on this side.
            float best = cos(gamma + float(side) * 0.5 * PI);
            for (uint j = 0u; j < ao.steps; j++) {
                float u = (float(j) + step_jitter) / float(ao.steps);
                float dist_px = (min_t + (1.0 - min_t) * u * u) * r_px;
                ivec2 sp = ivec2(floor(vec2(p) + 0.5 + float(side) * dist_px * omega));
                if (any(lessThan(sp, ivec2(0))) || any(greaterThanEqual(sp, ivec2(frame.size.xy)))) {
                    break;
                }
                float zs = imageLoad(pyramid, sp).r;
                if (zs <= 0.0) {
                    continue;
                }
                vec3 d = point_at_depth(sp, zs) - centre;
                float len = length(d);
                if (len > ao.radius || len <= 0.0) {
                    continue;
                }
                best = max(best, dot(d / len, v));
            }
            float h = float(side) * acos(clamp(best, -1.0, 1.0));
            h = gamma + clamp(h - gamma, -0.5 * PI, 0.5 * PI);
            arc += 0.25 * (-cos(2.0 * h - gamma) + cos(gamma) + 2.0 * h * sin(gamma));
        }
        visibility += np_len * arc;
    }
    imageStore(raw, p, vec4(visibility / float(ao.count), zc, 0.0, 0.0));
}
