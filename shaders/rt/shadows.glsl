// The soft-shadow estimator of the shadow passes (seed 001 §1.3): per pixel one visibility ray
// per light, towards a point sampled on the light: uniform over a rect light, uniform in the cone a
// sphere light (point and spot lights with a radius) subtends, in the cone of a directional
// light's angular radius; a radius of 0 gives the exact hard shadow. Output: the fraction of rays
// that reach the light, one layer per light, averaged over frames while the camera is still.
//
// Fixes of the thesis's code: the ray ends where it enters the sphere light (the thesis's
// `tmax = distance + radius` let geometry behind the light occlude it), origins are offset
// robustly instead of by tmin = 0.001, and a light below the surface's plane counts as shadowed
// without tracing (unless the surface transmits: then the ray leaves from its far side).
//
// The includer defines how rays are traced, after including hybrid.glsl:
//   bool shadow_occluded(vec3 from, vec3 ng, vec3 to)       the segment from a surface point
//   bool shadow_occluded_dir(vec3 from, vec3 ng, vec3 dir)  the unbounded ray
// (rt/shadows.comp: the BVH; rt/shadows_linespace*.comp: the line space.)
#ifndef KILN_SHADOWS_GLSL
#define KILN_SHADOWS_GLSL

// `through`: the surface transmits (KHR_materials_transmission), so a light behind it is traced
// from its far side.
float visibility(Primary s, GpuLight l, bool through) {
    vec3 wi;
    float dist;
    if (l.kind == LIGHT_DIRECTIONAL) {
        wi = l.radius > 0.0 ? sample_cone(-l.direction, cos(l.radius)) : -l.direction;
        dist = 3.4e38;
    } else if (l.kind == LIGHT_RECT) {
        // Behind a one-sided rect light's plane nothing arrives.
        if (dot(s.p - l.position, l.direction) <= 0.0) {
            return 1.0;
        }
        vec3 up = cross(l.direction, l.right);
        vec3 q = l.position + l.right * (rnd() - 0.5) * l.width + up * (rnd() - 0.5) * l.height;
        vec3 to = q - s.p;
        dist = length(to);
        wi = to / max(dist, 1e-30);
    } else {
        vec3 to = l.position - s.p;
        float d = length(to);
        vec3 axis = to / max(d, 1e-30);
        // Where the light contributes nothing (outside a spot's cone, beyond its range) the
        // composition multiplies zero by the visibility: no ray is traced.
        if ((l.kind == LIGHT_SPOT && dot(-axis, l.direction) <= l.cos_outer) || (l.range > 0.0 && d > l.range)) {
            return 1.0;
        }
        if (l.radius > 0.0 && d > l.radius) {
            float sin2 = (l.radius * l.radius) / (d * d);
            wi = sample_cone(axis, sqrt(max(1.0 - sin2, 0.0)));
            // Distance to where the ray enters the sphere.
            float b = dot(wi, to);
            dist = b - sqrt(max(b * b - (d * d - l.radius * l.radius), 0.0));
        } else {
            wi = axis;
            dist = d;
        }
    }
    float side = dot(wi, s.ng);
    if (side == 0.0 || (side < 0.0 && !through) || dist <= 0.0) {
        return 0.0;
    }
    vec3 ng = facing(s.ng, wi);
    if (l.kind == LIGHT_DIRECTIONAL) {
        return shadow_occluded_dir(s.p, ng, wi) ? 0.0 : 1.0;
    }
    return shadow_occluded(s.p, ng, s.p + wi * dist) ? 0.0 : 1.0;
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), frame.size.xy))) {
        return;
    }
    Primary s;
    bool surface = primary_at(pixel, s);
    bool through = surface && gbuffer_transmission(texelFetch(g_material, pixel, 0)) > 0.0;
    seed_rng(pixel, 1u);
    for (uint i = 0u; i < rt.shadow_lights; i++) {
        float v = surface ? visibility(s, lights[i], through) : 1.0;
        ivec3 at = ivec3(pixel, int(i));
        imageStore(rt_shadows, at, vec4(accumulate(imageLoad(rt_shadows, at).r, v)));
    }
}

#endif
