// Textures of the ray-traced passes, read from one texel buffer (portable: no descriptor
// indexing, which lavapipe lacks): every texture's mip chain as stored in the file, packed
// RGBA8 words or BC blocks (decoded here, bc.glsl), then swizzled as the file says.
// The includer declares `texels` (uint[]) and `textures` (GpuTexture[]) storage buffers.
#ifndef KILN_TEXTURES_GLSL
#define KILN_TEXTURES_GLSL

#include "bc.glsl"

// Whether the texel buffer holds BC blocks: a specialization constant the player sets per file
// from its textures' formats when it builds the pipelines (player/src/render/texels.rs). Left
// false, the driver drops every copy of the BC decoders before compiling, so a file without BC
// textures compiles as fast as before they existed; a BC file read with it false would decode
// its blocks as RGBA8 words.
layout(constant_id = 0) const bool TEXELS_BC = false;

int wrap(int i, int n, uint mode) {
    if (mode == 2u) {
        return clamp(i, 0, n - 1);
    }
    if (mode == 1u) {
        int m = ((i % (2 * n)) + 2 * n) % (2 * n);
        return m < n ? m : 2 * n - 1 - m;
    }
    return ((i % n) + n) % n;
}

// Pixel format: 0 RGBA8, 1 BC7, 2 BC5, 3 BC4.
uint texture_format(GpuTexture t) {
    return (t.flags >> TEXTURE_FORMAT_SHIFT) & 3u;
}

// Texel (x, y) of a level as stored (BC5: R, G, 0, 1; BC4: R, 0, 0, 1).
vec4 stored_texel(GpuTexture t, uvec3 level, uint x, uint y) {
    uint f = texture_format(t);
    if (!TEXELS_BC || f == 0u) {
        return unpackUnorm4x8(texels[level.z + y * level.x + x]);
    }
    uint block = (y >> 2u) * ((level.x + 3u) >> 2u) + (x >> 2u);
    uint i = (y & 3u) * 4u + (x & 3u);
    if (f == 3u) {
        uint w = level.z + 2u * block;
        return vec4(bc4_channel(texels[w], texels[w + 1u], i), 0.0, 0.0, 1.0);
    }
    uint w = level.z + 4u * block;
    uvec4 b = uvec4(texels[w], texels[w + 1u], texels[w + 2u], texels[w + 3u]);
    if (f == 2u) {
        return vec4(bc4_channel(b.x, b.y, i), bc4_channel(b.z, b.w, i), 0.0, 1.0);
    }
    return bc7_texel(b, i);
}

vec4 level_texel(GpuTexture t, uvec3 level, int x, int y) {
    x = wrap(x, int(level.x), (t.flags >> TEXTURE_WRAP_U_SHIFT) & 3u);
    y = wrap(y, int(level.y), (t.flags >> TEXTURE_WRAP_V_SHIFT) & 3u);
    vec4 c = stored_texel(t, level, uint(x), uint(y));
    if ((t.flags & TEXTURE_SRGB) != 0u) {
        c.rgb = srgb_to_linear(c.rgb);
    }
    // The swizzle: three bits per sampled channel, a stored channel (0..3), zero (4) or one (5).
    vec4 s;
    for (uint k = 0u; k < 4u; k++) {
        uint v = (t.flags >> (TEXTURE_SWIZZLE_SHIFT + 3u * k)) & 7u;
        s[k] = v < 4u ? c[v] : (v == 5u ? 1.0 : 0.0);
    }
    return s;
}

// Words of a `w × h` level: a word per texel, or four (BC7, BC5) or two (BC4) per 4×4 block.
uint level_words(GpuTexture t, uint w, uint h) {
    uint f = texture_format(t);
    uint blocks = ((w + 3u) >> 2u) * ((h + 3u) >> 2u);
    return !TEXELS_BC || f == 0u ? w * h : (f == 3u ? 2u * blocks : 4u * blocks);
}

// Mip level `level` of a texture: its size and first word.
uvec3 texture_level(GpuTexture t, uint level) {
    uint w = t.width, h = t.height, offset = t.offset;
    for (uint l = 0u; l < level; l++) {
        offset += level_words(t, w, h);
        w = max(w >> 1, 1u);
        h = max(h >> 1, 1u);
    }
    return uvec3(w, h, offset);
}

// Texture `t` at `uv`: level `l0` by its nearest texel or bilinearly, blended with level `l1` by
// `f` (trilinear). Every tap goes through one loop around one `level_texel` call, whose trip
// count the compiler cannot know: each call site is a copy of the BC decoders once inlined, and
// a copy per tap made the shaders so large that lavapipe took minutes to compile them.
vec4 filtered(GpuTexture t, vec2 uv, uint l0, uint l1, float f, bool nearest) {
    uint taps = nearest ? 1u : (f > 0.0 ? 8u : 4u);
    vec4 sum = vec4(0.0);
    for (uint k = 0u; k < taps; k++) {
        uvec3 l = texture_level(t, k < 4u ? l0 : l1);
        vec2 x = uv * vec2(l.xy) - (nearest ? 0.0 : 0.5);
        ivec2 i = ivec2(floor(x));
        vec2 fr = x - vec2(i);
        uint corner = k & 3u;
        ivec2 o = ivec2(int(corner & 1u), int(corner >> 1u));
        float w = nearest ? 1.0
                          : (o.x == 1 ? fr.x : 1.0 - fr.x) * (o.y == 1 ? fr.y : 1.0 - fr.y)
                * (k < 4u ? 1.0 - f : f);
        sum += w * level_texel(t, l, i.x + o.x, i.y + o.y);
    }
    return sum;
}

// Mip 0, bilinear or nearest as the texture's filter says, always deterministic (the traversal's
// alpha test: a ray's coverage must not change when it meets the same point again).
vec4 sample_texture(uint index, vec2 uv) {
    GpuTexture t = textures[index];
    return filtered(t, uv, 0u, 0u, 0.0, (t.flags & TEXTURE_LINEAR) == 0u);
}

#ifdef TEXTURE_STOCHASTIC
// Mip 0's bilinear filter by one texel: the corner chosen with probability equal to its bilinear
// weight (stochastic texture filtering, Pharr et al. 2024), from the includer's
// `texture_xi()` (uniform in [0, 1)). Its mean is the bilinear value, so an estimator linear in
// the texel (base colour, emission) stays unbiased, and one BC block is decoded instead of four.
// What is not linear in it (roughness, the normal) is filtered after shading, as a path tracer
// averaging many samples per pixel filters anyway.
vec4 stochastic_bilinear(GpuTexture t, vec2 uv) {
    uvec3 l = texture_level(t, 0u);
    vec2 x = uv * vec2(l.xy) - 0.5;
    ivec2 i = ivec2(floor(x));
    vec2 fr = x - vec2(i);
    ivec2 o = ivec2(texture_xi() < fr.x ? 1 : 0, texture_xi() < fr.y ? 1 : 0);
    return level_texel(t, l, i.x + o.x, i.y + o.y);
}
#endif

// Mip 0 of `t` as the texture's filter says; with TEXTURE_STOCHASTIC a bilinear filter reads one
// texel of its footprint (`stochastic_bilinear`: the same mean, for what an estimator is linear
// in, such as the emitted radiance next-event estimation reads at every vertex).
vec4 mip0(GpuTexture t, vec2 uv) {
    bool nearest = (t.flags & TEXTURE_LINEAR) == 0u;
#ifdef TEXTURE_STOCHASTIC
    if (!nearest) {
        return stochastic_bilinear(t, uv);
    }
#endif
    return filtered(t, uv, 0u, 0u, 0.0, nearest);
}

// Trilinear filtering with the level chosen from the uv footprint of a pixel (the larger of its
// two screen-axis derivatives, as isotropic hardware filtering does); magnification follows the
// texture's filter.
vec4 sample_texture_grad(uint index, vec2 uv, vec2 dx, vec2 dy) {
    GpuTexture t = textures[index];
    vec2 size = vec2(t.width, t.height);
    float footprint = max(length(dx * size), length(dy * size));
    // A degenerate pixel footprint (NaN, infinite) takes the coarsest level.
    footprint = isnan(footprint) || isinf(footprint) ? 1e30 : footprint;
    float levels = float((t.flags >> TEXTURE_LEVELS_SHIFT) & 31u);
    float lod = clamp(log2(max(footprint, 1e-8)), 0.0, max(levels - 1.0, 0.0));
    if (lod <= 0.0) {
        return mip0(t, uv);
    }
    uint l0 = min(uint(floor(lod)), uint(max(levels - 1.0, 0.0)));
    uint l1 = min(l0 + 1u, uint(levels) - 1u);
    return filtered(t, uv, l0, l1, lod - float(l0), false);
}

// A material's texture slots: bit k of a slot mask is slot k of `material_texels`' array.
const uint SLOT_BASE_COLOR = 0u;
const uint SLOT_METALLIC_ROUGHNESS = 1u;
const uint SLOT_NORMAL = 2u;
const uint SLOT_OCCLUSION = 3u;
const uint SLOT_EMISSIVE = 4u;
const uint SLOT_CLEARCOAT = 5u;            // R: clear coat strength
const uint SLOT_CLEARCOAT_ROUGHNESS = 6u;  // G: the coat's roughness
const uint SLOT_TRANSMISSION = 7u;         // R: transmission
const uint MATERIAL_SLOTS = 8u;
const uint ALL_MATERIAL_SLOTS = (1u << MATERIAL_SLOTS) - 1u;

uint material_texture(GpuMaterialLayout m, uint slot) {
    return slot == SLOT_BASE_COLOR ? m.base_color_texture
        : slot == SLOT_METALLIC_ROUGHNESS ? m.metallic_roughness_texture
        : slot == SLOT_NORMAL ? m.normal_texture
        : slot == SLOT_OCCLUSION ? m.occlusion_texture
        : slot == SLOT_EMISSIVE ? m.emissive_texture
        : slot == SLOT_CLEARCOAT ? m.clearcoat_texture
        : slot == SLOT_CLEARCOAT_ROUGHNESS ? m.clearcoat_roughness_texture
                                           : m.transmission_texture;
}

// The textures of material `m` in the slots of the mask `slots` at `uv` (trilinear by the
// derivatives `dx`, `dy`; zero derivatives give mip 0 as `sample_texture` does), white in the
// other slots and where the material has no texture. One loop around one sampling call, over
// the slots present (a trip count the compiler cannot know, so it stays a loop): every call
// site of a sampler is a copy of the texel fetch once inlined, BC decoders included, and a call
// site per slot multiplied the shaders the driver compiles.
void material_texels(GpuMaterialLayout m, uint slots, vec2 uv, vec2 dx, vec2 dy, out vec4 texel[MATERIAL_SLOTS]) {
    uint pending = 0u;
    for (uint k = 0u; k < MATERIAL_SLOTS; k++) {
        texel[k] = vec4(1.0);
        if (material_texture(m, k) != NO_TEXTURE) {
            pending |= 1u << k;
        }
    }
    pending &= slots;
    while (pending != 0u) {
        uint k = uint(findLSB(pending));
        pending &= pending - 1u;
        texel[k] = sample_texture_grad(material_texture(m, k), uv, dx, dy);
    }
}

#endif
