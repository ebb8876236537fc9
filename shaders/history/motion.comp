#version 460
// Reprojected accumulation of the ray-traced passes (`--aa taa`), step 1 of 2: per pixel, where
// its surface point was last frame (common/reproject.glsl) and how many frames of history it
// has there. The history restarts (0 frames) where there was no previous frame, where the point
// was behind the previous camera or off its image, and where the previous frame's depth at the
// point shows another surface (disoccluded: the 2 × 2 depths a bilinear read touches, widened by
// 1 %, must include the point's reprojected depth). A still camera keeps every pixel's own
// history and counts on (the running mean of `--aa accumulate`); a moving one caps the history
// at `cap` frames, so that what reprojection smears fades.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D depth;            // this frame's (G-buffer)
layout(set = 0, binding = 2) uniform sampler2D depth_before;     // the previous frame's
layout(set = 0, binding = 3) uniform sampler2D motion_before;    // the previous frame's motion
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D motion;  // at.xy, frames, 0
layout(set = 0, binding = 5, r32f) uniform writeonly image2D depth_now;
// The samples in each pixel's mean after this frame's blend (frames + 1): what the denoiser
// divides the per-sample variance by (shaders/denoise/).
layout(set = 0, binding = 6, r32f) uniform writeonly image2D samples;
layout(push_constant) uniform Push { float cap; } push;

#include "../common/reproject.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    float d = texelFetch(depth, pixel, 0).r;
    imageStore(depth_now, pixel, vec4(d));
    vec2 at;
    float depth_then;
    bool valid = reproject_pixel(pixel, d, at, depth_then);
    bool still = frame.jitter.z != 0.0;
    if (valid && !still) {
        ivec2 size = textureSize(depth_before, 0);
        ivec2 base = ivec2(floor(at - 0.5));
        float lo = 3.4e38, hi = 0.0;
        for (int i = 0; i < 4; ++i) {
            float z = texelFetch(depth_before, clamp(base + ivec2(i & 1, i >> 1), ivec2(0), size - 1), 0).r;
            lo = min(lo, z);
            hi = max(hi, z);
        }
        valid = depth_then >= lo * 0.99 && depth_then <= hi * 1.01;
    }
    float frames = 0.0;
    if (valid) {
        ivec2 q = clamp(ivec2(floor(at)), ivec2(0), ivec2(frame.size.xy) - 1);
        frames = texelFetch(motion_before, q, 0).z + 1.0;
        frames = still ? min(frames, 16777216.0) : min(frames, push.cap);
    }
    imageStore(motion, pixel, vec4(at, frames, 0.0));
    imageStore(samples, pixel, vec4(frames + 1.0));
}
