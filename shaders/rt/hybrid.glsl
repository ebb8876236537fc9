// What the hybrid ray-traced passes share (seed 001's shadows, AO and reflections, and GI, over the
// G-buffer, with kiln's compute traversal instead of a ray-tracing pipeline): one descriptor set,
// the exact surface point under a pixel, and progressive accumulation.
//
// Surface points are not reconstructed from depth: the G-buffer stores the triangle under each
// pixel, and the point is the pixel-centre camera ray's barycentric point on that triangle. It
// lies on the triangle within a few ulps of its corners, which is the error bound that
// `offset_ray_origin` (Wächter and Binder 2019) is built for; a depth-reconstructed point can be
// off the surface by far more (depth quantisation, the inverse projection), which is what forces
// fixed epsilons.
#ifndef KILN_HYBRID_GLSL
#define KILN_HYBRID_GLSL

#include "../common/layout.glsl"
#include "../common/packing.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
#include "../common/scene_bindings.glsl"   // bindings 1-8: the scene, the lights
layout(set = 0, binding = 9, std430) readonly buffer Texels { uint texels[]; };
layout(set = 0, binding = 10, std430) readonly buffer Textures { GpuTexture textures[]; };
layout(set = 0, binding = 11, std430) readonly buffer RasterIndices { uint raster_indices[]; }; // draw order
layout(set = 0, binding = 12) uniform usampler2D g_triangle;
layout(set = 0, binding = 13) uniform sampler2D g_normal;
layout(set = 0, binding = 14) uniform sampler2D g_albedo;
layout(set = 0, binding = 15) uniform sampler2D g_material;
layout(set = 0, binding = 16, r32f) uniform image2DArray rt_shadows;   // one layer per light
layout(set = 0, binding = 17, r32f) uniform image2D rt_ao;
layout(set = 0, binding = 18, rgba32f) uniform image2D rt_reflections;  // rgb, a = 1 where traced
// Between the two reflection passes, per reflection sample: the radiance without the lights'
// shadowed terms (a = 1 where traced), the hit's offset origin (w = 1 on a hit), and each
// light's unshadowed term, which the lean shadow pass adds where the light is visible (then the
// same for the hit of a metal hit's own reflection, and that hit's origin: reflections.comp).
layout(set = 0, binding = 19, rgba32f) uniform image2D refl_partial;
layout(set = 0, binding = 20, rgba32f) uniform image2D refl_origin;
layout(set = 0, binding = 21, rgba32f) uniform image2DArray refl_lights;
// The emitter table of next-event estimation (`common/emitters.glsl`; `rt.emitters` entries) and
// each triangle's entry in it, and the GI target: mean incoming radiance over the cosine-weighted
// hemisphere (irradiance / π), rgb.
layout(set = 0, binding = 22, std430) readonly buffer Emitters { GpuEmitter emitters[]; };
layout(set = 0, binding = 23, std430) readonly buffer TriEmitters { int tri_emitter[]; };
layout(set = 0, binding = 24, rgba32f) uniform image2D rt_gi;
// Direct light of the emissive triangles (`direct.glsl`): the emissive-triangle table its
// candidates are drawn from (`rt.emissive` entries: corners, emission and an alias table by power),
// the light it estimates (rgb, reflected towards the camera), each pixel's reservoir as the last
// frame left it and as this frame's candidates leave it (emissive entry, the point on it as two
// unorm16, the contribution weight's bits, the candidates it stands for), and the surface each
// reservoir was made at (position, octahedral normal as two halves).
layout(set = 0, binding = 25, std430) readonly buffer Emissive { GpuEmissive emissive[]; };
layout(set = 0, binding = 26, rgba32f) uniform image2D rt_direct;
layout(set = 0, binding = 27, rgba32ui) uniform uimage2D reservoirs_then;
layout(set = 0, binding = 28, rgba32ui) uniform uimage2D reservoirs_now;
layout(set = 0, binding = 29, rgba32f) uniform image2D surfaces_then;
// The environment (`common/environment.glsl`): bindings 30-31.
#define ENV_BINDING 30
#include "../common/environment.glsl"
// The compiler's irradiance probes (`common/probes.glsl`), which light the reflections' hits
// where the file has them (`probe_volume.dims.x` 0: it has none, and the rest are placeholders);
// the line space's bindings follow at 36.
layout(set = 0, binding = 32) uniform ProbeVolume { ProbeConstants probe_volume; };
layout(set = 0, binding = 33) uniform sampler2DArray probe_irradiance_atlas;
layout(set = 0, binding = 34) uniform sampler2DArray probe_visibility_atlas;
layout(set = 0, binding = 35, std430) readonly buffer ProbeStates { vec4 probe_states[]; };
layout(push_constant) uniform Params { RtConstants rt; };

#include "../common/random.glsl"
#include "../common/scene.glsl"
#include "../common/pixel.glsl"
#include "../common/probes.glsl"

// The visible surface under a pixel.
struct Primary {
    vec3 p;     // on the triangle
    vec3 ng;    // geometric normal, towards the camera
    vec3 n;     // shading normal from the G-buffer, on the camera's side of the surface
    vec3 v;     // unit vector towards the camera
};

bool primary_at(ivec2 pixel, out Primary s) {
    uint id = texelFetch(g_triangle, pixel, 0).r;
    if (id == 0u) {
        return false;
    }
    uint t = id - 1u;
    uvec3 idx = uvec3(raster_indices[3u * t], raster_indices[3u * t + 1u], raster_indices[3u * t + 2u]);
    vec3 p0 = vertex_position(idx.x), p1 = vertex_position(idx.y), p2 = vertex_position(idx.z);
    vec3 dir = pixel_ray(vec2(pixel) + 0.5);
    // Barycentrics of the pixel-centre ray, clamped onto the triangle (the rasteriser's sample
    // may lie a hair outside the triangle that won it).
    vec3 e1 = p1 - p0, e2 = p2 - p0;
    vec2 b = barycentrics(pixel_origin(vec2(pixel) + 0.5), dir, p0, e1, e2);
    float u = clamp(b.x, 0.0, 1.0);
    float w = clamp(b.y, 0.0, 1.0 - u);
    s.p = p0 + u * e1 + w * e2;
    vec3 ng = cross(e1, e2);
    ng = dot(ng, ng) > 0.0 ? normalize(ng) : -normalize(dir);
    if (dot(ng, dir) > 0.0) {
        ng = -ng;
    }
    s.ng = ng;
    vec3 n = oct_decode(texelFetch(g_normal, pixel, 0).rg);
    s.n = dot(n, ng) < 0.0 ? -n : n;
    s.v = -normalize(dir);
    return true;
}

// Seeds the generator for this pixel, pass and frame.
void seed_rng(ivec2 pixel, uint pass) {
    rng = hash(uint(pixel.x) + 65536u * uint(pixel.y)) ^ hash(rt.seed * 0x9e3779b9u + pass * 0x85ebca6bu);
}

// The running mean over frames: the new sample weighs 1 / (n + 1) after n accumulated frames.
float accumulate(float old, float value) {
    return rt.accumulated == 0u ? value : old + (value - old) / float(rt.accumulated + 1u);
}

vec4 accumulate(vec4 old, vec4 value) {
    return rt.accumulated == 0u ? value : old + (value - old) / float(rt.accumulated + 1u);
}

// A direction uniformly distributed in the cone of half-angle acos(cos_max) around `axis`.
vec3 sample_cone(vec3 axis, float cos_max) {
    float c = 1.0 - rnd() * (1.0 - cos_max);
    float s = sqrt(max(1.0 - c * c, 0.0));
    float phi = 2.0 * PI * rnd();
    return basis(axis) * vec3(s * cos(phi), s * sin(phi), c);
}

#endif
