// Tangent-space normal mapping through the cotangent frame of the surface's position and uv
// differentials across the pixel (Schüler 2013): no stored tangents needed. The raster G-buffer
// passes dFdx/dFdy; the visibility-buffer resolve passes the differentials of the neighbouring
// pixels' rays on the same triangle, so both give the same frame.
#ifndef KILN_NORMALMAP_GLSL
#define KILN_NORMALMAP_GLSL

// A normal map's tangent-space normal from a sampled texel: x and y from red and green, z
// reconstructed as sqrt(1 - x² - y²). Every normal map goes through this one path, so a map
// stored as two channels (BC5, whose blue samples 0) and one stored as RGBA8 shade alike.
vec3 normal_texel(vec4 texel) {
    vec2 xy = texel.xy * 2.0 - 1.0;
    return vec3(xy, sqrt(max(1.0 - dot(xy, xy), 0.0)));
}

vec3 normal_mapped(vec3 n, vec3 dp1, vec3 dp2, vec2 duv1, vec2 duv2, vec3 sample_ts, float scale) {
    vec3 dp2perp = cross(dp2, n);
    vec3 dp1perp = cross(n, dp1);
    // The cotangent frame is ±(dp/du, dp/dv): the sign of (dp1 × dp2)·n. Schüler's formula
    // assumes it positive, as OpenGL's window y (up) gives; Vulkan's y runs down the framebuffer
    // (dFdy, and the resolve's next row), which negated both axes and turned every normal map's
    // tilt by 180° about the normal against the path tracer's.
    float side = dot(cross(dp1, dp2), n) < 0.0 ? -1.0 : 1.0;
    vec3 t = (dp2perp * duv1.x + dp1perp * duv2.x) * side;
    vec3 b = (dp2perp * duv1.y + dp1perp * duv2.y) * side;
    float invmax = inversesqrt(max(max(dot(t, t), dot(b, b)), 1e-20));
    vec3 m = vec3(sample_ts.xy * scale, sample_ts.z);
    // glTF uv runs down the image; its tangent-space y (green) points up: flip the bitangent.
    return normalize(mat3(t * invmax, -b * invmax, n) * m);
}

#endif
