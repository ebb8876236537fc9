// The packed pyramid texel of screen-space GI (pack.comp writes it, gather.comp and
// upsample.glsl read it): 16 bytes, one fetch per sample. Words:
//   0: half2(p.x, p.y)  1: half2(p.z, light.r)  2: half2(light.g, light.b)
//   3: half(tilt) in the low 16 bits, snorm8 × 2 (n_enc) in the high 16
// p is the surface point relative to the camera position (half floats hold it to 1/2048 of its
// distance: millimetres at metres, below what the gather resolves), light its lit radiance
// premultiplied by the lit fraction, tilt the seed's cos α / cos β (clamped to [0.001, 1000]:
// how much more surface than a pixel's camera-facing area the texel shows), n_enc its
// octahedral normal to 1/127 (about half a degree). The sky (and texels without a surface) store p = 0, which no surface has (it would be the
// eye): `packed_surface` tells them apart.
// The includer declares `frame` and includes screen_ao.glsl.
#ifndef KILN_SSGI_PACKED_GLSL
#define KILN_SSGI_PACKED_GLSL

uvec4 pack_texel(vec3 p, vec3 light, float tilt, vec2 n_enc) {
    uint last = (packHalf2x16(vec2(tilt, 0.0)) & 0xffffu) | (packSnorm4x8(vec4(n_enc, 0.0, 0.0)) << 16);
    return uvec4(packHalf2x16(p.xy), packHalf2x16(vec2(p.z, light.r)), packHalf2x16(light.gb), last);
}

float packed_tilt(uvec4 t) {
    return unpackHalf2x16(t.w).x;
}

vec3 packed_point(uvec4 t) {
    return vec3(unpackHalf2x16(t.x), unpackHalf2x16(t.y).x);
}

vec3 packed_light(uvec4 t) {
    return vec3(unpackHalf2x16(t.y).y, unpackHalf2x16(t.z));
}

vec2 packed_normal(uvec4 t) {
    return unpackSnorm4x8(t.w >> 16).xy;
}

bool packed_surface(vec3 p) {
    return dot(p, p) > 0.0;
}

#endif
