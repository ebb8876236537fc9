#version 460
// Mitchell's occlusion image (`--media mitchell`, seed 002 §5) for one light, at a fraction of
// the screen's resolution: 1 where that light's emitter is seen, 0 where an occluder is. The
// emitter is the sky for a directional light (the sun comes through wherever the sky shows) and
// the light's own rectangle for a rect light, and a sphere of radius `gc.extent` around a point
// or spot light (the seed's light-coloured cube), drawn where they lie in front of the surface. The blur reads it bilinearly, which is the
// seed's anti-aliasing for a small occlusion image.
#include "../common/layout.glsl"
#include "../common/lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, std430) readonly buffer Lights { GpuLight lights[]; };
layout(set = 0, binding = 2) uniform sampler2D g_depth;
layout(set = 0, binding = 3, r16f) uniform writeonly image2D occlusion;
layout(push_constant) uniform Push { GodRayConstants gc; };

#include "../common/pixel.glsl"

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(occlusion);
    if (any(greaterThanEqual(texel, size))) {
        return;
    }
    // The screen point at the texel's centre.
    vec2 at = (vec2(texel) + 0.5) * vec2(frame.size.xy) / vec2(size);
    ivec2 pixel = min(ivec2(at), ivec2(frame.size.xy) - 1);
    vec3 o = pixel_origin(at);
    vec3 d = normalize(pixel_ray(at));
    float t_surface = surface_distance(at, texelFetch(g_depth, pixel, 0).r, o, d);
    GpuLight l = lights[gc.light];
    float emitter = 0.0;
    if (l.kind == LIGHT_DIRECTIONAL) {
        emitter = t_surface == SKY_DISTANCE ? 1.0 : 0.0;
    } else if (l.kind == LIGHT_RECT) {
        emitter = rect_light_hit(l, o, d, t_surface) > 0.0 ? 1.0 : 0.0;
    } else {
        float t = dot(l.position - o, d);
        vec3 miss = o + d * t - l.position;
        emitter = t > 0.0 && t < t_surface && dot(miss, miss) <= gc.extent * gc.extent ? 1.0 : 0.0;
    }
    imageStore(occlusion, texel, vec4(emitter));
}
