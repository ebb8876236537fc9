#version 460
#extension GL_EXT_control_flow_attributes : require
// Mitchell's radial blur (`--media mitchell`, seed 002 §5, Listing A.4) for one light: from each
// pixel, `gc.samples` samples of the occlusion image towards the light's screen position, the
// march covering 1/density of the way, each weighted by decay^i, summed with the pixel's own
// sample and scaled by the exposure per sample; the amount times the light's shaft radiance
// (godrays.glsl) is added to the scene's radiance. The seed's density divides the step (its
// listing's semantics, the inverse of GPU Gems'), there is no Weight factor, and the exposure
// is per sample so that the image does not brighten with the sample count.
#include "../common/layout.glsl"
#include "../common/lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1, std430) readonly buffer Lights { GpuLight lights[]; };
layout(set = 0, binding = 2, std430) readonly buffer Media { GpuMedium media[]; };
layout(set = 0, binding = 3) uniform sampler2D occlusion;
layout(set = 0, binding = 4, rgba32f) uniform image2D radiance;
layout(push_constant) uniform Push { GodRayConstants gc; };

#include "../common/pixel.glsl"
#include "../common/media.glsl"
#include "../common/godrays.glsl"

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
    vec2 uv = at / vec2(frame.size.xy);
    vec2 step = (uv - light_uv) / (float(max(gc.samples, 1u)) * gc.step);
    float sum = on_screen(occlusion, uv);
    float weight = 1.0;
    vec2 p = uv;
    [[dont_unroll]] for (uint i = 0u; i < gc.samples; i++) {
        p -= step;
        sum += weight * on_screen(occlusion, p);
        weight *= gc.decay;
    }
    vec4 l0 = imageLoad(radiance, pixel);
    imageStore(radiance, pixel, vec4(l0.rgb + gc.gain * sum * colour, l0.a));
}
