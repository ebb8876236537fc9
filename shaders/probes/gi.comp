#version 460
// Diffuse GI from the compiler's irradiance probes (player/src/render/passes/probes.rs; FORMAT.md,
// "Irradiance probes"): per pixel, the probes' light at the visible surface (`common/probes.glsl`:
// DDGI's lookup over the baked volume, the point moved along its normal and towards the camera).
// Output: the mean incoming radiance of the surface (rgb), which the direct pass multiplies by
// the diffuse albedo in place of the sky's ambient (FRAME_RT_GI), as for the ray-traced GI; and,
// with the same weights, the irradiance along the mirror direction of the view, which the
// direct pass's split sum takes for its incoming radiance in place of the sky's
// (FRAME_PROBE_SPECULAR), so that metal indoors reflects the lit room and not the sky outside it.
// Alpha of both: the probes' confidence, below 1 past the volume's outermost probes on a side
// the surface faces out of, where the direct pass blends towards the unoccluded sky.
#include "../common/layout.glsl"
#include "../common/packing.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D g_depth;
layout(set = 0, binding = 2) uniform sampler2D g_normal;
// The probe volume (`common/probes.glsl`).
layout(set = 0, binding = 3) uniform sampler2DArray probe_irradiance_atlas;
layout(set = 0, binding = 4) uniform sampler2DArray probe_visibility_atlas;
layout(set = 0, binding = 5, std430) readonly buffer States { vec4 probe_states[]; };
layout(set = 0, binding = 6, rgba32f) uniform writeonly image2D gi_out;
layout(set = 0, binding = 7, rgba16f) uniform writeonly image2D specular_out;
layout(push_constant) uniform Push { ProbeConstants probes; };
#include "../common/pixel.glsl"
#include "../common/probes.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    float depth = texelFetch(g_depth, pixel, 0).r;
    if (!(depth > 0.0)) {
        imageStore(gi_out, pixel, vec4(0.0));
        imageStore(specular_out, pixel, vec4(0.0));
        return;
    }
    vec3 p = world_at_depth(vec2(pixel) + 0.5, depth);
    vec3 n = oct_decode(texelFetch(g_normal, pixel, 0).rg);
    vec3 v = towards_camera(p);
    if (dot(n, v) < 0.0) {
        n = -n;
    }
    // The emissive surfaces' light the probes saw directly counts unless the direct pass
    // estimates it (FRAME_RT_DIRECT).
    ProbeLight light = probe_light(probes, p, n, v, (frame.size.w & FRAME_RT_DIRECT) == 0u);
    imageStore(gi_out, pixel, vec4(light.irradiance, light.confidence));
    imageStore(specular_out, pixel, vec4(light.mirror, light.confidence));
}
