#version 460
#extension GL_EXT_control_flow_attributes : require
// Sousa's last pass (`--media sousa`, seed 002 §6, pass 5) for one light, at the screen's
// resolution: the third radial sum of the second pass's image (read bilinearly) times the
// light's shaft radiance (godrays.glsl), added to the scene's radiance. The effect is
// monochrome in the seed; here it takes the light's and the medium's colour.
#include "../common/layout.glsl"
#include "../common/lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, std430) readonly buffer Lights { GpuLight lights[]; };
layout(set = 0, binding = 2, std430) readonly buffer Media { GpuMedium media[]; };
layout(set = 0, binding = 3) uniform sampler2D previous;
layout(set = 0, binding = 4, rgba32f) uniform image2D radiance;
layout(push_constant) uniform Push { GodRayConstants gc; };

#include "../common/pixel.glsl"
#include "../common/media.glsl"
#include "../common/godrays.glsl"
#include "sum.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    GpuLight l = lights[gc.light];
    vec2 light_uv;
    if (!light_on_screen(l, light_uv)) {
        return;
    }
    vec2 at = vec2(pixel) + 0.5;
    vec3 colour = shaft_radiance(l, normalize(pixel_ray(at)), gc.media);
    if (all(equal(colour, vec3(0.0)))) {
        return;
    }
    float amount = sousa_sum(previous, at / vec2(frame.size.xy), light_uv);
    vec4 l0 = imageLoad(radiance, pixel);
    imageStore(radiance, pixel, vec4(l0.rgb + amount * colour, l0.a));
}
