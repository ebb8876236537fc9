// Octahedral normal encoding (Meyer et al. 2010), as in format/src/linespace/pnmt.rs; colour
// helpers (sRGB, luminance, the denoiser's albedo demodulation).
#ifndef KILN_PACKING_GLSL
#define KILN_PACKING_GLSL

vec2 oct_encode(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 p = n.xy;
    if (n.z < 0.0) {
        p = (1.0 - abs(p.yx)) * vec2(p.x >= 0.0 ? 1.0 : -1.0, p.y >= 0.0 ? 1.0 : -1.0);
    }
    return p;
}

vec3 oct_decode(vec2 e) {
    float z = 1.0 - abs(e.x) - abs(e.y);
    float t = max(-z, 0.0);
    return normalize(vec3(e.x - t * (e.x >= 0.0 ? 1.0 : -1.0), e.y - t * (e.y >= 0.0 ? 1.0 : -1.0), z));
}

vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

vec3 linear_to_srgb(vec3 l) {
    l = clamp(l, 0.0, 1.0);
    return mix(l * 12.92, 1.055 * pow(l, vec3(1.0 / 2.4)) - 0.055, greaterThan(l, vec3(0.0031308)));
}

// Relative luminance of linear Rec. 709 (sRGB primaries) radiance.
float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

// What the denoiser (shaders/denoise/) divides a demodulated signal by before it filters and
// multiplies back after (albedo demodulation): the surface's linear base colour, at least 0.05
// per channel so that black and purely specular surfaces keep their light. The signal's
// second moment (its alpha) is taken of the same quotient.
vec3 demodulator(vec3 base) {
    return max(base, vec3(0.05));
}

// The G-buffer material target's blue channel (8 bits, common/dielectric.glsl): 255 a
// diffuse-only material, 128..254 a thin-walled transmission of (k − 127) / 127 (its F0 glTF's
// core 0.04), 0..125 the coded grey F0 of an opaque one.
#define GBUFFER_TRANSMISSION_STEPS 127.0

bool gbuffer_diffuse_only(vec4 mat) {
    return mat.b * 255.0 > 254.5;
}

float gbuffer_transmission(vec4 mat) {
    float k = round(mat.b * 255.0);
    float t = k - GBUFFER_TRANSMISSION_STEPS;
    return t >= 1.0 && t <= GBUFFER_TRANSMISSION_STEPS ? t / GBUFFER_TRANSMISSION_STEPS : 0.0;
}

#endif
