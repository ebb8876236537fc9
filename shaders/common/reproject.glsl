// Reprojection into the previous frame (`--aa taa`, and the passes that keep a history): where
// this frame's pixel showed its surface point last frame. The includer declares the `frame` uniform
// (FrameConstants: `reproject`, `jitter`).
#ifndef KILN_REPROJECT_GLSL
#define KILN_REPROJECT_GLSL

#include "pixel.glsl"

// Where the surface point of `pixel` (this frame's reversed-Z depth `d`, sky 0) lay in the
// previous frame's image, in pixels with that frame's pixel centres at k + ½ (this frame's
// jitter taken out: the history holds pixel centres); `depth_then` its reversed-Z depth in the
// previous projection. False without a previous frame, behind the previous camera or off its
// image. A still camera gives the pixel's own centre.
bool reproject_pixel(ivec2 pixel, float d, out vec2 at, out float depth_then) {
    at = vec2(pixel) + 0.5;
    depth_then = d;
    if (frame.jitter.w != 0.0) {
        return false;
    }
    if (frame.jitter.z != 0.0) {
        return true;
    }
    vec4 previous = frame.reproject * vec4(image_to_ndc(at), d, 1.0);
    // The sky (depth 0) reprojects as a direction, w still positive; a point behind the
    // previous camera has w ≤ 0.
    if (!(previous.w > 0.0)) {
        return false;
    }
    vec3 p = previous.xyz / previous.w;
    at = ndc_to_image(p.xy) - frame.jitter.xy;
    depth_then = p.z;
    return all(greaterThanEqual(at, vec2(0.0))) && all(lessThanEqual(at, vec2(frame.size.xy)));
}

#endif
