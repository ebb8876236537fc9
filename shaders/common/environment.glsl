// The environment (FORMAT.md, "Environment"; format/src/environment.rs): radiance from beyond the
// scene in every direction, its GGX-prefiltered levels, its irradiance harmonics and the alias
// table that draws directions in proportion to its light. The includer defines ENV_BINDING (the
// first of two storage-buffer bindings in set 0, player/src/scene/environment.rs) and includes
// layout.glsl first. A file without an environment has a zero header (`env_present()` false):
// every function then returns the constant sky it is given, so a caller needs no second path.
//
// Directions map as Mitsuba 3's envmap (y up): u = atan2(x, -z) / 2pi wrapped, v = acos(y) / pi.
#ifndef KILN_ENVIRONMENT_GLSL
#define KILN_ENVIRONMENT_GLSL

#include "packing.glsl"

layout(set = 0, binding = ENV_BINDING, std430) readonly buffer Environment {
    EnvironmentHeader environment;
    uint env_texels[];  // the radiance map, then the prefiltered levels (E5B9G9R9)
};
layout(set = 0, binding = ENV_BINDING + 1, std430) readonly buffer EnvironmentTable {
    EnvironmentCell env_cells[];
};

const float ENV_PI = 3.14159265358979;

bool env_present() {
    return environment.map.x != 0u;
}

vec2 env_uv(vec3 d) {
    float u = atan(d.x, -d.z) * (0.5 / ENV_PI);
    u -= floor(u);
    return vec2(u >= 1.0 ? 0.0 : u, acos(clamp(d.y, -1.0, 1.0)) * (1.0 / ENV_PI));
}

vec3 env_direction(vec2 uv) {
    float phi = 2.0 * ENV_PI * uv.x, theta = ENV_PI * uv.y;
    float st = sin(theta);
    return vec3(st * sin(phi), cos(theta), -st * cos(phi));
}

vec3 env_decode(uint t) {
    float scale = exp2(float(int(t >> 27u)) - 24.0);
    return vec3(float(t & 511u), float((t >> 9u) & 511u), float((t >> 18u) & 511u)) * scale;
}

// Bilinear in a w x h map whose first texel is env_texels[first] (u wraps, v clamps).
vec3 env_bilinear(uint first, uint w, uint h, vec2 uv) {
    vec2 p = uv * vec2(w, h) - 0.5;
    vec2 f = p - floor(p);
    ivec2 i = ivec2(floor(p));
    int x0 = (i.x % int(w) + int(w)) % int(w), x1 = (x0 + 1) % int(w);
    int y0 = clamp(i.y, 0, int(h) - 1), y1 = clamp(i.y + 1, 0, int(h) - 1);
    vec3 a = env_decode(env_texels[first + uint(y0) * w + uint(x0)]);
    vec3 b = env_decode(env_texels[first + uint(y0) * w + uint(x1)]);
    vec3 c = env_decode(env_texels[first + uint(y1) * w + uint(x0)]);
    vec3 d = env_decode(env_texels[first + uint(y1) * w + uint(x1)]);
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// Radiance arriving from unit direction d (the constant `sky` without an environment).
vec3 env_radiance(vec3 d, vec3 sky) {
    if (!env_present()) {
        return sky;
    }
    return env_bilinear(0u, environment.map.x, environment.map.y, env_uv(d));
}

// The split sum's prefiltered radiance around unit direction r for a GGX roughness (level i holds
// roughness i / (levels - 1); between levels, linear).
vec3 env_filtered(vec3 r, float roughness, vec3 sky) {
    if (!env_present()) {
        return sky;
    }
    uint levels = environment.filtered.z;
    float lod = clamp(roughness, 0.0, 1.0) * float(levels - 1u);
    uint l0 = min(uint(lod), levels - 1u);
    uint l1 = min(l0 + 1u, levels - 1u);
    vec2 uv = env_uv(r);
    uint first = environment.filtered.w;
    vec3 c0 = vec3(0.0), c1 = vec3(0.0);
    for (uint l = 0u; l <= l1; l++) {
        uint w = max(environment.filtered.x >> l, 2u), h = w / 2u;
        if (l == l0) {
            c0 = env_bilinear(first, w, h, uv);
        }
        if (l == l1) {
            c1 = env_bilinear(first, w, h, uv);
        }
        first += w * h;
    }
    return mix(c0, c1, lod - float(l0));
}

// The environment's nine harmonics (irradiance / pi, band l holding the cosine lobe's factor
// A_l = 1, 2/3, 1/4) evaluated at unit direction n with band l further scaled by band[l].
vec3 env_harmonics(vec3 n, vec3 band) {
    float b[9] = float[9](0.2820948, 0.4886025 * n.y, 0.4886025 * n.z, 0.4886025 * n.x,
                          1.0925484 * n.x * n.y, 1.0925484 * n.y * n.z, 0.31539157 * (3.0 * n.z * n.z - 1.0),
                          1.0925484 * n.x * n.z, 0.5462742 * (n.x * n.x - n.y * n.y));
    vec3 e = vec3(0.0);
    for (int k = 0; k < 9; k++) {
        e += environment.sh[k].rgb * b[k] * band[k == 0 ? 0 : (k < 4 ? 1 : 2)];
    }
    return max(e, vec3(0.0));
}

// Mean radiance over the cosine-weighted hemisphere around unit normal n (irradiance / pi): a
// Lambertian surface of albedo a reflects a times this.
vec3 env_irradiance(vec3 n, vec3 sky) {
    if (!env_present()) {
        return sky;
    }
    return env_harmonics(n, vec3(1.0));
}

// How much sharper the environment is about unit direction d than its irradiance there: its
// level prefiltered for a lobe (`filtered`, env_filtered's answer about d) over its mean
// cosine-weighted radiance, by luminance (1 under the constant sky), bounded where the irradiance
// is near black. What turns light known as a cosine lobe about the mirror direction (the
// probes') into a glossy lobe's.
float env_sharpness(vec3 d, vec3 filtered, vec3 sky) {
    float spread = luminance(env_irradiance(d, sky));
    return spread > 0.0 ? clamp(luminance(filtered) / spread, 0.0, 8.0) : 1.0;
}

// Solid-angle density with which env_sample draws unit direction d.
float env_pdf(vec3 d) {
    if (!env_present()) {
        return 0.0;
    }
    uint w = environment.table.x, h = environment.table.y;
    vec2 uv = env_uv(d);
    uint x = min(uint(uv.x * float(w)), w - 1u), y = min(uint(uv.y * float(h)), h - 1u);
    float s = sqrt(max(1.0 - d.y * d.y, 0.0));
    return s > 0.0 ? env_cells[y * w + x].density / s : 0.0;
}

// A direction drawn from the table with three uniforms (the first picks the cell and, by its
// fraction, whether the cell keeps the draw; the other two place it in the cell), and its density
// (0: nothing to draw).
vec3 env_sample(vec3 xi, out float pdf) {
    pdf = 0.0;
    if (!env_present()) {
        return vec3(0.0, 1.0, 0.0);
    }
    uint w = environment.table.x, h = environment.table.y;
    float scaled = xi.x * float(w * h);
    uint cell = min(uint(scaled), w * h - 1u);
    EnvironmentCell c = env_cells[cell];
    float density = c.density;
    if (scaled - float(cell) >= c.keep) {
        cell = c.alias;
        density = c.alias_density;
    }
    vec2 uv = vec2((float(cell % w) + xi.y) / float(w), (float(cell / w) + xi.z) / float(h));
    vec3 d = env_direction(uv);
    float s = sin(ENV_PI * uv.y);
    pdf = s > 0.0 ? density / s : 0.0;
    return d;
}

#endif
