// What the screen-space AO passes share (player/src/render/passes/{depth_pyramid,sao,gtao,ao}.rs):
// the layout of the camera-space depth pyramid, points rebuilt from it, the projected radius
// and the per-pixel rotation. The includer declares the `frame` uniform (FrameConstants) and,
// where it reads the pyramid, `pyramid` (r32f image).
#ifndef KILN_SCREEN_AO_GLSL
#define KILN_SCREEN_AO_GLSL

#include "pixel.glsl"

// Levels of the pyramids: 0 (the screen's size) to PYRAMID_TOP, each side halved (rounded up);
// seven halvings take 1920 × 1080 to 15 × 9, whose diagonal screen-space GI's 40-pixel radius
// spans.
const int PYRAMID_TOP = 7;

// Where level `level` starts in the pyramid image: level 0 at the origin, levels 1.. stacked in
// one column to its right (x = the screen's width, y = the heights of the levels above it).
ivec2 pyramid_origin(int level) {
    if (level == 0) {
        return ivec2(0);
    }
    ivec2 s = ivec2(frame.size.xy);
    int y = 0;
    for (int k = 1; k < level; k++) {
        s = (s + 1) / 2;
        y += s.y;
    }
    return ivec2(int(frame.size.x), y);
}

// The size of level `level`.
ivec2 pyramid_size(int level) {
    ivec2 s = ivec2(frame.size.xy);
    for (int k = 0; k < level; k++) {
        s = (s + 1) / 2;
    }
    return s;
}

// The world point of screen pixel `pixel` (full resolution) at camera depth z (the distance
// along the camera's forward axis): pixel_ray has a forward component of 1.
vec3 point_at_depth(ivec2 pixel, float z) {
    vec2 at = vec2(pixel) + 0.5;
    return pixel_origin(at) + pixel_ray(at) * z;
}

// Screen pixels per world unit at camera depth z (across the image plane), the seed's S'/z.
float pixels_per_unit(float z) {
    float half_height = frame.camera_up.w * (camera_orthographic() ? 1.0 : z);
    return float(frame.size.y) / (2.0 * half_height);
}

// A per-pixel rotation in [0, 1) (the seed's φ / 2π): a 4 × 4 ordered-dither pattern, so that any
// 4 × 4 block of pixels holds the 16 rotations (k + ½)/16 once each and the blur averages them.
float pixel_rotation(ivec2 p) {
    const uint bayer[16] = uint[16](0u, 8u, 2u, 10u, 12u, 4u, 14u, 6u, 3u, 11u, 1u, 9u, 15u, 7u, 13u, 5u);
    return (float(bayer[(p.y & 3) * 4 + (p.x & 3)]) + 0.5) / 16.0;
}

#endif
