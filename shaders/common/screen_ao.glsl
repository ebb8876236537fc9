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

// The rotated-grid child of level texel q in the level below, of size `below` (McGuire et al.
// 2012, §2.2: child (1 − y mod 2, 1 − x mod 2), clamped into the level).
ivec2 pyramid_child(ivec2 q, ivec2 below) {
    return min(2 * q + ivec2((q.y & 1) ^ 1, (q.x & 1) ^ 1), below - 1);
}

// The camera depth (distance along the camera's forward axis) of image point `at` at reversed-Z
// `depth`.
float camera_depth(vec2 at, float depth) {
    return dot(world_at_depth(at, depth) - pixel_origin(at), frame.camera_forward.xyz);
}

// The world point of level `level`'s texel `t` at camera depth z: through the centre of the
// texel's block of full-resolution pixels (pixel_ray has a forward component of 1).
vec3 level_point(ivec2 t, int level, float z) {
    vec2 at = (vec2(t) + 0.5) * float(1 << level);
    return pixel_origin(at) + pixel_ray(at) * z;
}

// The world point of screen pixel `pixel` (full resolution) at camera depth z.
vec3 point_at_depth(ivec2 pixel, float z) {
    return level_point(pixel, 0, z);
}

// World units per screen pixel at camera depth z (across the image plane).
float units_per_pixel(float z) {
    return 2.0 * frame.camera_up.w * (camera_orthographic() ? 1.0 : z) / float(frame.size.y);
}

// Screen pixels per world unit at camera depth z, the seed's S'/z (its inverse).
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
