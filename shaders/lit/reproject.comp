#version 460
// Level 0 of the lit-radiance pyramid (seed 000 §3.5, its texture 8): the previous frame's final
// linear radiance, read bilinearly where each of this frame's pixels showed its surface point
// then (common/reproject.glsl), so that screen-space GI and reflections gather light that the
// previous frame lit, indirect light included (the seed's infinite bounces). Alpha 1 where there
// is such light, 0 where there is none: the sky (the GI adds the sky's ambient itself), no
// previous frame, or a point off the previous image or behind its camera. A surface disoccluded
// since the previous frame takes the light of whatever covered it then, for one frame.
// On a frame without history the player makes the pyramid a second time after the direct pass
// (`gi.current` 1): level 0 is then this frame's radiance where it lies, so that the first frame
// already shows its screen-space reflections and GI (player/src/render/frame.rs, `again`).
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D depth_tex;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D radiance_before;
layout(set = 0, binding = 3, rgba16f) uniform writeonly image2D lit;
layout(push_constant) uniform Push { ScreenGiConstants gi; };

#include "../common/reproject.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), frame.size.xy))) {
        return;
    }
    float d = texelFetch(depth_tex, p, 0).r;
    vec2 at;
    float depth_then;
    vec4 out_lit = vec4(0.0);
    bool found = gi.current != 0u;
    if (found) {
        at = vec2(p) + 0.5;
    } else {
        found = reproject_pixel(p, d, at, depth_then);
    }
    if (d > 0.0 && found) {
        ivec2 size = ivec2(frame.size.xy);
        vec2 x = at - 0.5;
        ivec2 base = ivec2(floor(x));
        vec2 f = x - vec2(base);
        vec3 sum = vec3(0.0);
        for (int i = 0; i < 4; i++) {
            ivec2 o = ivec2(i & 1, i >> 1);
            float w = (o.x == 0 ? 1.0 - f.x : f.x) * (o.y == 0 ? 1.0 - f.y : f.y);
            sum += w * imageLoad(radiance_before, clamp(base + o, ivec2(0), size - 1)).rgb;
        }
        // Half floats hold up to 65504; what does not fit is clamped rather than turned into
        // infinity, which the gathers would spread.
        out_lit = vec4(min(max(sum, vec3(0.0)), vec3(65000.0)), 1.0);
    }
    imageStore(lit, p, out_lit);
}
