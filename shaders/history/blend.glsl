// Reprojected accumulation of the ray-traced passes (`--aa taa`), step 2 of 2, for one target:
// the pass wrote this frame's sample (no running mean of its own); here it is blended into the
// target's history read at the pixel's reprojected point (bilinearly; a still camera reads the
// pixel's own texel), weighing 1/(n + 1) after n frames of history (motion.comp), and the
// result written to the target and, as the next frame's history, to `history_now`. Included by
// one shader per target kind, which defines LAYERED (an array, `push.layers` layers) and FORMAT
// (the image format qualifier).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D motion;
#ifdef LAYERED
layout(set = 0, binding = 2, FORMAT) uniform image2DArray target;
layout(set = 0, binding = 3) uniform sampler2DArray history_before;
layout(set = 0, binding = 4, FORMAT) uniform writeonly image2DArray history_now;
#else
layout(set = 0, binding = 2, FORMAT) uniform image2D target;
layout(set = 0, binding = 3) uniform sampler2D history_before;
layout(set = 0, binding = 4, FORMAT) uniform writeonly image2D history_now;
#endif
// step: screen pixels per target texel along each axis (2 for half-resolution reflections,
// whose texel c is traced from pixel 2c); layers: of a layered target.
layout(push_constant) uniform Push { uint step; uint layers; } push;

void main() {
    ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(target).xy;
    if (any(greaterThanEqual(cell, size))) {
        return;
    }
    vec4 m = imageLoad(motion, cell * int(push.step));
    float frames = m.z;
    // The reprojected point in target texels: texel c holds the sample of pixel c · step, whose
    // centre c · step + ½ maps to the texel's centre c + ½ (a still camera's motion is the
    // pixel's own centre, so it reads its own texel).
    vec2 at = (m.xy - 0.5) / float(push.step) + 0.5;
    vec2 uv = at / vec2(size);
    float w = 1.0 / (frames + 1.0);
#ifdef LAYERED
    for (uint layer = 0u; layer < push.layers; ++layer) {
        ivec3 c = ivec3(cell, int(layer));
        vec4 now = imageLoad(target, c);
        vec4 v = frames > 0.0 ? mix(textureLod(history_before, vec3(uv, float(layer)), 0.0), now, w) : now;
        imageStore(target, c, v);
        imageStore(history_now, c, v);
    }
#else
    vec4 now = imageLoad(target, cell);
    vec4 v = frames > 0.0 ? mix(textureLod(history_before, uv, 0.0), now, w) : now;
    imageStore(target, cell, v);
    imageStore(history_now, cell, v);
#endif
}
