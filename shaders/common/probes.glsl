// The compiler's irradiance probes (FORMAT.md, "Irradiance probes") looked up at a surface point:
// DDGI's lookup (Majercik et al., JCGT 2019, §4; 2021) over a baked volume. One copy for the
// probe GI pass (`probes/gi.comp`, at the visible surfaces) and the ray-traced reflections
// (`rt/reflections.comp`, at their hits).
//
// The point moves a little along its normal and towards the viewer (so that its own surface does
// not shadow it in the probes' distance maps); the eight probes of the cell around it are each
// weighted by
//  - trilinear interpolation;
//  - how much the probe lies in front of the surface: ((cos + 1) / 2)² + 0.2 of the angle between
//    the normal and the direction to it (light from behind a surface cannot reach it, but a
//    wholly behind probe still beats no probe);
//  - Chebyshev's bound on the chance that nothing nearer than the point lies between the probe
//    and the point, from the probe's mean and mean square distance along that direction (cubed;
//    at least 0.05), so that a probe on the other side of a wall barely counts;
// with weights below 0.2 crushed towards 0 (DDGI's). Probes switched off (inside geometry) are
// skipped.
//
// The includer includes layout.glsl and packing.glsl first and declares
//   sampler2DArray probe_irradiance_atlas   E5B9G9R9 mean cosine-weighted radiance; layer z (light
//                                           but emitters seen directly), then layer dims.z + z
//                                           (emitters seen directly) when the volume has two
//   sampler2DArray probe_visibility_atlas   (mean, mean square) distance in spacings
//   vec4 probe_states[]                     per probe: offset from its grid point, 1 on / 0 off
#ifndef KILN_PROBES_GLSL
#define KILN_PROBES_GLSL

// The normalised coordinates of direction d in the tile of probe column `probe` (n interior
// texels and a one-texel border per tile) of an atlas of `size` texels.
vec2 probe_tile_uv(uvec2 probe, vec3 d, uint n, vec2 size) {
    vec2 e = oct_encode(d) * 0.5 + 0.5;
    return (vec2(probe * (n + 2u)) + 1.0 + e * float(n)) / size;
}

// The mean cosine-weighted radiance probe `c` holds around direction d (and the emitters it
// sees directly when `emitted`).
vec3 probe_irradiance(ProbeConstants pv, ivec3 c, vec3 d, vec2 size, bool emitted) {
    vec2 uv = probe_tile_uv(uvec2(c.xy), d, pv.irradiance_texels, size);
    vec3 e = texture(probe_irradiance_atlas, vec3(uv, float(c.z))).rgb;
    if (emitted) {
        e += texture(probe_irradiance_atlas, vec3(uv, float(c.z + int(pv.dims.z)))).rgb;
    }
    return e;
}

// What the probes say of a surface point.
struct ProbeLight {
    vec3 irradiance;   // mean incoming radiance over the cosine-weighted hemisphere of the normal
    vec3 mirror;       // the same around the mirror direction of the view (a cosine lobe standing
                       // in for the glossy lobe, as DDGI's glossy fallback does)
    float confidence;  // below 1 past the volume's outermost probes on a side the surface faces
                       // out of, where the caller blends towards the unoccluded sky
};

// The probes' light at point p of unit normal n (on the side of unit v, the direction towards the
// viewer), with the emitters the probes saw directly when `emitted` (and the volume has them).
ProbeLight probe_light(ProbeConstants pv, vec3 p, vec3 n, vec3 v, bool emitted) {
    emitted = emitted && pv.layers > 1u;
    vec3 mirror = reflect(-v, n);
    vec3 biased = p + n * pv.normal_bias + v * pv.view_bias;
    ivec3 dims = ivec3(pv.dims);
    vec3 g = (biased - pv.origin) / pv.spacing;
    ivec3 base = clamp(ivec3(floor(g)), ivec3(0), max(dims - 2, ivec3(0)));
    vec3 alpha = clamp(g - vec3(base), 0.0, 1.0);
    vec2 irradiance_size = vec2(pv.dims.xy * (pv.irradiance_texels + 2u));
    vec2 visibility_size = vec2(pv.dims.xy * (pv.visibility_texels + 2u));
    vec3 sum = vec3(0.0), sum_mirror = vec3(0.0);
    float total = 0.0;
    for (int i = 0; i < 8; i++) {
        ivec3 corner = ivec3(i & 1, (i >> 1) & 1, i >> 2);
        ivec3 c = min(base + corner, dims - 1);
        vec4 state = probe_states[c.x + dims.x * (c.y + dims.y * c.z)];
        if (state.w == 0.0) {
            continue;
        }
        vec3 probe = pv.origin + vec3(c) * pv.spacing + state.xyz;
        vec3 trilinear = mix(1.0 - alpha, alpha, vec3(corner));
        float weight = 1.0;
        float facing = (dot(normalize(probe - p), n) + 1.0) * 0.5;
        weight *= facing * facing + 0.2;
        vec3 from_probe = biased - probe;
        float distance = length(from_probe);
        vec3 dir = distance > 0.0 ? from_probe / distance : n;
        vec2 moments = texture(probe_visibility_atlas,
                               vec3(probe_tile_uv(uvec2(c.xy), dir, pv.visibility_texels, visibility_size), float(c.z))).rg;
        float r = distance / pv.spacing;
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
        sum += weight * probe_irradiance(pv, c, n, irradiance_size, emitted);
        sum_mirror += weight * probe_irradiance(pv, c, mirror, irradiance_size, emitted);
        total += weight;
    }
    float inverse = total > 0.0 ? 1.0 / total : 0.0;
    // Beyond the outermost probes on a side where the surface faces out of the volume (a car's
    // roof at the top of its bounds, a helmet's crown), no probe lies on the side the surface
    // sees, only ones behind or under it (inside the car): the volume ends there, and what lies
    // beyond it is the sky. The caller blends towards its unoccluded sky light by how far past
    // the last layer the lookup point lies (half a spacing: all sky; the outermost layer lies a
    // quarter to three quarters of a spacing inside the bounds, and the lookup point moves 0.1
    // along the normal and 0.2 towards the viewer) times how squarely the surface faces out (a
    // unit normal's component: each product stays within [0, 1]). A surface facing back into
    // the volume (a room's wall at its bounds) keeps the probes.
    vec3 last = vec3(max(dims - 1, ivec3(0)));
    vec3 out_hi = clamp(2.0 * (g - last), 0.0, 1.0) * max(n, vec3(0.0));
    vec3 out_lo = clamp(-2.0 * g, 0.0, 1.0) * max(-n, vec3(0.0));
    vec3 out_most = max(out_hi, out_lo);
    ProbeLight light;
    light.irradiance = sum * inverse;
    light.mirror = sum_mirror * inverse;
    light.confidence = 1.0 - max(max(out_most.x, out_most.y), out_most.z);
    return light;
}

#endif
