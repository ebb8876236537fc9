// Textures of the ray-traced passes, read from one texel buffer (portable: no descriptor
// indexing, which lavapipe lacks): every texture's mip chain as packed RGBA8 words.
// The includer declares `texels` (uint[]) and `textures` (GpuTexture[]) storage buffers.
#ifndef KILN_TEXTURES_GLSL
#define KILN_TEXTURES_GLSL

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

vec4 level_texel(GpuTexture t, uvec3 level, int x, int y) {
    x = wrap(x, int(level.x), (t.flags >> TEXTURE_WRAP_U_SHIFT) & 3u);
    y = wrap(y, int(level.y), (t.flags >> TEXTURE_WRAP_V_SHIFT) & 3u);
    vec4 c = unpackUnorm4x8(texels[level.z + uint(y) * level.x + uint(x)]);
    if ((t.flags & TEXTURE_SRGB) != 0u) {
        c.rgb = srgb_to_linear(c.rgb);
    }
    return c;
}

vec4 texel(GpuTexture t, int x, int y) {
    return level_texel(t, uvec3(t.width, t.height, t.offset), x, y);
}

// Mip level `level` of a texture: its size and first word.
uvec3 texture_level(GpuTexture t, uint level) {
    uint w = t.width, h = t.height, offset = t.offset;
    for (uint l = 0u; l < level; l++) {
        offset += w * h;
        w = max(w >> 1, 1u);
        h = max(h >> 1, 1u);
    }
    return uvec3(w, h, offset);
}

vec4 bilinear_level(GpuTexture t, uint level, vec2 uv) {
    uvec3 l = texture_level(t, level);
    vec2 x = uv * vec2(l.xy) - 0.5;
    ivec2 i = ivec2(floor(x));
    vec2 f = x - vec2(i);
    return mix(mix(level_texel(t, l, i.x, i.y), level_texel(t, l, i.x + 1, i.y), f.x),
        mix(level_texel(t, l, i.x, i.y + 1), level_texel(t, l, i.x + 1, i.y + 1), f.x), f.y);
}

// Mip 0, bilinear or nearest as the texture's filter says (what the path tracer samples).
vec4 sample_texture(uint index, vec2 uv) {
    GpuTexture t = textures[index];
    if ((t.flags & TEXTURE_LINEAR) == 0u) {
        vec2 x = uv * vec2(t.width, t.height);
        return texel(t, int(floor(x.x)), int(floor(x.y)));
    }
    return bilinear_level(t, 0u, uv);
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
        return sample_texture(index, uv);
    }
    uint l0 = min(uint(floor(lod)), uint(max(levels - 1.0, 0.0)));
    vec4 a = bilinear_level(t, l0, uv);
    float f = lod - float(l0);
    return f > 0.0 ? mix(a, bilinear_level(t, min(l0 + 1u, uint(levels) - 1u), uv), f) : a;
}

#endif
