#version 460
// The depth pyramid's levels 0 to `ao.level` (at most 5) in one dispatch, for a nearest
// reduction without normals (SAO's): each workgroup turns a 32 × 32 block of pixels into its
// camera depths (level 0) and reduces them in shared memory, level by level, to one texel of
// level 5. A nearest reduction copies one child of each 2 × 2 block (the same rotated-grid
// child as reduce.comp), so a block's texels at every level depend on that block's pixels
// alone: no barrier between workgroups, no pass per level.
#include "../common/layout.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2, r32f) uniform writeonly image2D pyramid;
layout(push_constant) uniform Push { ScreenAoConstants ao; };

#include "../common/screen_ao.glsl"

shared float level_z[16][16];

// Level 0 at pixel p (as linear.comp): its camera depth, 0 on the sky.
float level0(ivec2 p) {
    float depth = texelFetch(depth_tex, p, 0).r;
    return depth > 0.0 ? max(camera_depth(vec2(p) + 0.5, depth), 1e-6) : 0.0;
}

void main() {
    ivec2 lid = ivec2(gl_LocalInvocationID.xy);
    ivec2 block = ivec2(gl_WorkGroupID.xy);
    ivec2 screen = ivec2(frame.size.xy);
    // Level 0: this thread's 2 × 2 pixels; level 1: the texel they make.
    ivec2 q = block * 16 + lid;
    float z[4];
    for (int k = 0; k < 4; k++) {
        ivec2 p = 2 * q + ivec2(k & 1, k >> 1);
        z[k] = 0.0;
        if (all(lessThan(p, screen))) {
            z[k] = level0(p);
            imageStore(pyramid, p, vec4(z[k]));
        }
    }
    int top = int(ao.level);
    if (top < 1) {
        return;
    }
    // Texels beyond a level's size (the screen's edge blocks) keep 0: their clamped children
    // would lie in another block.
    float z1 = 0.0;
    if (all(lessThan(q, pyramid_size(1)))) {
        ivec2 c = pyramid_child(q, screen) - 2 * q;
        z1 = z[c.x + 2 * c.y];
        imageStore(pyramid, pyramid_origin(1) + q, vec4(z1));
    }
    level_z[lid.y][lid.x] = z1;
    // Levels 2 to top: the first (16 >> (level − 1))² threads each make one texel.
    for (int level = 2; level <= top; level++) {
        barrier();
        int side = 16 >> (level - 1);
        float zl = 0.0;
        ivec2 ql = block * side + lid;
        bool working = all(lessThan(lid, ivec2(side)));
        bool inside = working && all(lessThan(ql, pyramid_size(level)));
        if (inside) {
            ivec2 cl = pyramid_child(ql, pyramid_size(level - 1)) - 2 * block * side;
            zl = level_z[cl.y][cl.x];
        }
        barrier();
        if (working) {
            level_z[lid.y][lid.x] = zl;
        }
        if (inside) {
            imageStore(pyramid, pyramid_origin(level) + ql, vec4(zl));
        }
    }
}
