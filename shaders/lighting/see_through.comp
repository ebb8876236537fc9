#version 460
// The see-through layer over the lit frame (passes/see_through.rs): where see-through surfaces
// (glTF BLEND, KHR_materials_transmission's thin walls) lie in front of the opaque one, the
// radiance becomes
//   a · front + exp(−absorbed) · behind
// with `behind` the frame lit so far (the opaque surfaces), `front` the nearest see-through
// surface's own light (the direct pass over its G-buffer: its reflection, the diffuse part its
// transmission leaves, the lights behind it through its transmitted lobe, its emission), `a`
// its coverage (a blended surface's alpha, the chance the path tracer meets it; else 1), and
// `absorbed` the sum over every see-through surface in front of the opaque one of −ln(a T +
// 1 − a), T the share of the light from straight behind it that it lets through
// (`gbuffer/gbuffer.glsl`). For one surface that is a · (front + T · behind) + (1 − a) · behind.
#include "../common/layout.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
// The layer (`gbuffer/see_through.frag`): depth 0 where no see-through surface is in front of
// the opaque one.
layout(set = 0, binding = 1) uniform sampler2D s_depth;
layout(set = 0, binding = 2) uniform sampler2D s_coverage;
layout(set = 0, binding = 3) uniform sampler2D s_absorbed;
// The nearest surface's own light, and the frame's radiance (read behind, written over).
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D s_radiance;
layout(set = 0, binding = 5, rgba32f) uniform image2D radiance;
// Where the layer was drawn this frame (x0, y0, x1, y1, exclusive; passes/see_through.rs
// `screen_area`): outside it its targets are undefined.
layout(push_constant) uniform Area { uvec4 area; };

void main() {
    // Dispatched over the area alone.
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy + area.xy);
    if (any(greaterThanEqual(uvec2(pixel), min(area.zw, frame.size.xy)))) {
        return;
    }
    if (!(texelFetch(s_depth, pixel, 0).r > 0.0)) {
        return;
    }
    float a = clamp(texelFetch(s_coverage, pixel, 0).r, 0.0, 1.0);
    vec3 passed = exp(-max(texelFetch(s_absorbed, pixel, 0).rgb, vec3(0.0)));
    vec4 front = imageLoad(s_radiance, pixel);
    if (front.a == 0.0) {
        // A rect light in front of the layer's surface: the opaque pass shows it already.
        return;
    }
    vec3 behind = imageLoad(radiance, pixel).rgb;
    imageStore(radiance, pixel, vec4(a * front.rgb + passed * behind, 1.0));
}
