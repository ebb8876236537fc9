#version 460
// Diffuse GI from the compiler's irradiance probes (player/src/render/passes/probes.rs; FORMAT.md,
// "Irradiance probes"): DDGI's lookup (Majercik et al., JCGT 2019, §4; 2021) over a baked volume.
// Per pixel, the surface point moves a little along its normal and towards the camera (so that
// its own surface does not shadow it in the probes' distance maps); the eight probes of the cell
// around it are each weighted by
//  - trilinear interpolation;
//  - how much the probe lies in front of the surface: ((cos + 1) / 2)² + 0.2 of the angle between
//    the normal and the direction to it (light from behind a surface cannot reach it, but a
//    wholly behind probe still beats no probe);
//  - Chebyshev's bound on the chance that nothing nearer than the point lies between the probe
//    and the point, from the probe's mean and mean square distance along that direction (cubed;
//    at least 0.05), so that a probe on the other side of a wall barely counts;
// with weights below 0.2 crushed towards 0 (DDGI's). The irradiance (mean cosine-weighted
// radiance) is read along the normal. Probes switched off (inside geometry) are skipped.
// Output: the mean incoming radiance of the surface (rgb), which the direct pass multiplies by
// the diffuse albedo in place of the sky's ambient (FRAME_RT_GI), as for the ray-traced GI; and,
// with the same weights, the irradiance along the mirror direction of the view, which the
// direct pass's split sum takes for its incoming radiance in place of the sky's
// (FRAME_PROBE_SPECULAR): a cosine lobe stands in for the glossy lobe, as DDGI's glossy
// fallback does, so that metal indoors reflects the lit room and not the sky outside it.
// Alpha of both: the probes' confidence, below 1 past the volume's outermost probes on a side
// the surface faces out of, where the direct pass blends towards the unoccluded sky.
#include "../common/layout.glsl"
#include "../common/packing.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameConstants frame; };
layout(set = 0, binding = 1) uniform sampler2D g_depth;
layout(set = 0, binding = 2) uniform sampler2D g_normal;
// E5B9G9R9 mean cosine-weighted radiance; layer z (light but emitters seen directly), then
// layer dims.z + z (emitters seen directly) when the volume has two layers.
layout(set = 0, binding = 3) uniform sampler2DArray irradiance;
// (mean, mean square) distance in spacings.
layout(set = 0, binding = 4) uniform sampler2DArray visibility;
// Per probe: offset from its grid point (scene units), and 1 on / 0 off.
layout(set = 0, binding = 5, std430) readonly buffer States { vec4 states[]; };
layout(set = 0, binding = 6, rgba32f) uniform writeonly image2D gi_out;
layout(set = 0, binding = 7, rgba16f) uniform writeonly image2D specular_out;
layout(push_constant) uniform Push { ProbeConstants probes; };
#include "../common/pixel.glsl"

// The normalised coordinates of direction d in the tile of probe column `probe` (n interior
// texels and a one-texel border per tile) of an atlas of `size` texels.
vec2 tile_uv(uvec2 probe, vec3 d, uint n, vec2 size) {
    vec2 e = oct_encode(d) * 0.5 + 0.5;
    return (vec2(probe * (n + 2u)) + 1.0 + e * float(n)) / size;
}

// The mean cosine-weighted radiance probe `c` holds around direction d (and the emitters it
// sees directly when `emitted`).
vec3 probe_irradiance(ivec3 c, vec3 d, vec2 size, bool emitted) {
    vec2 uv = tile_uv(uvec2(c.xy), d, probes.irradiance_texels, size);
    vec3 e = texture(irradiance, vec3(uv, float(c.z))).rgb;
    if (emitted) {
        e += texture(irradiance, vec3(uv, float(c.z + int(probes.dims.z)))).rgb;
    }
    return e;
}

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
    vec3 mirror = reflect(-v, n);
    vec3 biased = p + n * probes.normal_bias + v * probes.view_bias;
    ivec3 dims = ivec3(probes.dims);
    vec3 g = (biased - probes.origin) / probes.spacing;
    ivec3 base = clamp(ivec3(floor(g)), ivec3(0), max(dims - 2, ivec3(0)));
    vec3 alpha = clamp(g - vec3(base), 0.0, 1.0);
    vec2 irradiance_size = vec2(probes.dims.xy * (probes.irradiance_texels + 2u));
    vec2 visibility_size = vec2(probes.dims.xy * (probes.visibility_texels + 2u));
    bool emitted = probes.layers > 1u && (frame.size.w & FRAME_RT_DIRECT) == 0u;
    vec3 sum = vec3(0.0), sum_mirror = vec3(0.0);
    float total = 0.0;
    for (int i = 0; i < 8; i++) {
        ivec3 corner = ivec3(i & 1, (i >> 1) & 1, i >> 2);
        ivec3 c = min(base + corner, dims - 1);
        vec4 state = states[c.x + dims.x * (c.y + dims.y * c.z)];
        if (state.w == 0.0) {
            continue;
        }
        vec3 probe = probes.origin + vec3(c) * probes.spacing + state.xyz;
        vec3 trilinear = mix(1.0 - alpha, alpha, vec3(corner));
        float weight = 1.0;
        float facing = (dot(normalize(probe - p), n) + 1.0) * 0.5;
        weight *= facing * facing + 0.2;
        vec3 from_probe = biased - probe;
        float distance = length(from_probe);
        vec3 dir = distance > 0.0 ? from_probe / distance : n;
        vec2 moments = texture(visibility, vec3(tile_uv(uvec2(c.xy), dir, probes.visibility_texels, visibility_size), float(c.z))).rg;
        float r = distance / probes.spacing;
        if (r > moments.x) {
            float variance = abs(moments.y - moments.x * moments.x);
            float beyond = r - moments.x;
            float chebyshev = variance / (variance + beyond * beyond);
            weight *= max(chebyshev * chebyshev * chebyshev, 0.05);
        }
        weight = max(weight, 1e-6);
        const float CRUSH = 0.2;
        if (weight < CRUSH) {
            weight *= weight * weight / (CRUSH * CRUSH);
        }
        weight *= trilinear.x * trilinear.y * trilinear.z;
        sum += weight * probe_irradiance(c, n, irradiance_size, emitted);
        sum_mirror += weight * probe_irradiance(c, mirror, irradiance_size, emitted);
        total += weight;
    }
    float inverse = total > 0.0 ? 1.0 / total : 0.0;
    // Beyond the outermost probes on a side where the surface faces out of the volume (a car's
    // roof at the top of its bounds, a helmet's crown), no probe lies on the side the surface
    // sees, only ones behind or under it (inside the car): the volume ends there, and what lies
    // beyond it is the sky. The direct pass blends towards its unoccluded sky light by how far
    // past the last layer the lookup point lies (half a spacing: all sky; the outermost layer
    // lies a quarter to three quarters of a spacing inside the bounds, and the lookup point moves
    // 0.1 along the normal and 0.2 towards the eye) times how squarely the surface faces out (a
    // unit normal's component: each product stays within [0, 1]). A surface facing back into the
    // volume (a room's wall at its bounds) keeps the probes.
    vec3 last = vec3(max(dims - 1, ivec3(0)));
    vec3 out_hi = clamp(2.0 * (g - last), 0.0, 1.0) * max(n, vec3(0.0));
    vec3 out_lo = clamp(-2.0 * g, 0.0, 1.0) * max(-n, vec3(0.0));
    vec3 out_most = max(out_hi, out_lo);
    float sky = max(max(out_most.x, out_most.y), out_most.z);
    imageStore(gi_out, pixel, vec4(sum * inverse, 1.0 - sky));
    imageStore(specular_out, pixel, vec4(sum_mirror * inverse, 1.0 - sky));
}
