// Analytic-light terms shared by the passes that shade with `GpuLight` (include layout.glsl
// first).
#ifndef KILN_LIGHTS_GLSL
#define KILN_LIGHTS_GLSL

// A spot light's cone falloff for the unit direction `l` from the shaded point towards the
// light: smoothstep from cos_outer to cos_inner, written out because GLSL leaves smoothstep
// undefined for equal edges.
float spot_cone(GpuLight light, vec3 l) {
    float t = clamp((dot(-l, light.direction) - light.cos_outer) / max(light.cos_inner - light.cos_outer, 1e-6), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// The light of `l` arriving unoccluded at point p, as the media passes take it: `wl` the unit
// direction towards the light, `dist` the distance to it (3.4e38 for a directional light), and
// the irradiance on a surface facing it: a directional light's radiance, I/d² for point and
// spot lights (times the cone), and a rect light as a point of intensity L·A·cos at its centre.
// False where nothing arrives: at the light itself, or beyond its range.
bool light_at_point(GpuLight l, vec3 p, out vec3 wl, out float dist, out vec3 e) {
    if (l.kind == LIGHT_DIRECTIONAL) {
        wl = -l.direction;
        dist = 3.4e38;
        e = l.radiance;
        return true;
    }
    vec3 to = l.position - p;
    float d2 = dot(to, to);
    dist = sqrt(d2);
    wl = vec3(0.0);
    e = vec3(0.0);
    if (!(dist > 0.0) || (l.range > 0.0 && dist > l.range)) {
        return false;
    }
    wl = to / dist;
    e = l.radiance / d2;
    if (l.kind == LIGHT_SPOT) {
        e *= spot_cone(l, wl);
    } else if (l.kind == LIGHT_RECT) {
        e *= l.width * l.height * max(dot(-wl, l.direction), 0.0);
    }
    return true;
}

// Where the ray origin + t·dir meets the emitting (front) side of rect light `light`: t, if
// within (0, tmax) and the light's range; -1 otherwise. `dir` need not be unit length (t and
// the range are then in its units).
float rect_light_hit(GpuLight light, vec3 origin, vec3 dir, float tmax) {
    float denom = dot(dir, light.direction);
    if (denom >= 0.0) {
        return -1.0;
    }
    float t = dot(light.position - origin, light.direction) / denom;
    if (t <= 0.0 || t >= tmax || (light.range > 0.0 && t > light.range)) {
        return -1.0;
    }
    vec3 q = origin + dir * t - light.position;
    vec3 up = cross(light.direction, light.right);
    if (abs(dot(q, light.right)) > 0.5 * light.width || abs(dot(q, up)) > 0.5 * light.height) {
        return -1.0;
    }
    return t;
}

#endif
