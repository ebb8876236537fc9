// The scene as the ray-traced passes see it: textures from a texel buffer, alpha-masked
// traversal, surfaces at hits (shading frame, material), and the glTF metallic-roughness BRDF
// (its pieces from brdf.glsl) with its sampling. Shared by the reference path tracer and the
// hybrid passes so that both shade a hit identically.
//
// The includer declares these storage buffers (see shaders/reference/pathtrace.comp):
//   bvh_nodes, bvh_tris (traverse.glsl), vertex_data (6 floats per vertex), vertex_attributes,
//   indices (leaf order), tri_materials, materials, texels, textures
// and includes random.glsl, layout.glsl and packing.glsl first.
#ifndef KILN_SCENE_GLSL
#define KILN_SCENE_GLSL

#include "brdf.glsl"
#include "dielectric.glsl"
#include "lights.glsl"
#include "textures.glsl"
#include "vertices.glsl"
#include "normalmap.glsl"

vec2 triangle_uv(uint tri, float u, float v) {
    uvec3 idx = uvec3(indices[3u * tri], indices[3u * tri + 1u], indices[3u * tri + 2u]);
    return (1.0 - u - v) * vertex_uv(idx.x) + u * vertex_uv(idx.y) + v * vertex_uv(idx.z);
}

vec4 triangle_color(uint tri, float u, float v) {
    uvec3 idx = uvec3(indices[3u * tri], indices[3u * tri + 1u], indices[3u * tri + 2u]);
    return interpolated_color(idx, u, v);
}

// A uniform number in [0, 1) for a point of a triangle (PCG's output permutation over the
// triangle and the hit's barycentrics): what decides whether a ray meets a blended surface.
float coverage_number(uint tri, float u, float v) {
    uint x = tri * 747796405u ^ floatBitsToUint(u) * 2891336453u ^ floatBitsToUint(v) * 277803737u;
    x = x * 747796405u + 2891336453u;
    x = ((x >> ((x >> 28u) + 4u)) ^ x) * 277803737u;
    x = (x >> 22u) ^ x;
    return float(x >> 8u) * (1.0 / 16777216.0);
}

// Alpha-masked materials are cut out during traversal; alpha-blended ones are met with
// probability alpha (stochastic coverage: the path tracer's unbiased reading of blending, so
// that light passes a surface of alpha a with weight 1 − a, on every ray kind alike, shadow rays
// included). The number comes from the hit point, not the ray: rays meet a blended surface at
// ever different points, and a ray that returns to one point decides as before.
bool bvh_alpha_test(uint tri, float u, float v) {
    GpuMaterialLayout m = materials[tri_materials[tri]];
    uint mode = (m.flags >> MATERIAL_ALPHA_SHIFT) & 3u;
    if (mode == 0u) {
        return true;
    }
    float a = m.base_color.a * triangle_color(tri, u, v).a;
    if (m.base_color_texture != NO_TEXTURE) {
        a *= sample_texture(m.base_color_texture, triangle_uv(tri, u, v)).a;
    }
    return mode == 1u ? a >= m.alpha_cutoff : coverage_number(tri, u, v) < a;
}
#define BVH_ALPHA_TEST
#include "../common/traverse.glsl"

// ---------------------------------------------------------------- surfaces
struct Surface {
    vec3 p;
    vec3 ng;        // geometric normal, facing the incoming ray
    vec3 ns;        // shading normal, same side as ng
    vec3 nc;        // the clear coat's normal: the interpolated normal (no normal map), same side
    bool front;     // the ray hit the triangle's front (counter-clockwise) face
    Material mat;
    vec3 emission;  // emitted radiance towards the ray (zero from a back face of a one-sided material)
    uint triangle;  // the triangle hit (leaf order)
};

// The slots `surface_textured` reads (occlusion is the raster G-buffer's alone); the emissive
// texture only where the material emits.
uint surface_slots(GpuMaterialLayout m) {
    uint slots = (1u << SLOT_BASE_COLOR) | (1u << SLOT_METALLIC_ROUGHNESS) | (1u << SLOT_NORMAL);
    if (m.clearcoat > 0.0) {
        slots |= (1u << SLOT_CLEARCOAT) | (1u << SLOT_CLEARCOAT_ROUGHNESS);
    }
    if (m.transmission > 0.0) {
        slots |= 1u << SLOT_TRANSMISSION;
    }
    return any(greaterThan(m.emission, vec3(0.0))) ? slots | (1u << SLOT_EMISSIVE) : slots;
}

// The material of a surface from its textures' texels (`material_texels`) and vertex colour
// `color`: s.mat and s.emission (towards the side s.front says the ray came from).
void surface_textured(inout Surface s, GpuMaterialLayout m, vec4 texel[MATERIAL_SLOTS], vec4 color) {
    vec4 base = m.base_color * color * texel[SLOT_BASE_COLOR];
    s.mat.base = base.rgb;
    vec4 mr = texel[SLOT_METALLIC_ROUGHNESS];
    s.mat.metallic = clamp(m.metallic * mr.b, 0.0, 1.0);
    s.mat.roughness = clamp(m.roughness * mr.g, 0.0, 1.0);
    s.mat.diffuse_only = (m.flags & MATERIAL_DIFFUSE_ONLY) != 0u;
    material_dielectric(m, s.mat.f0, s.mat.f90);
    s.mat.clearcoat = clamp(m.clearcoat * texel[SLOT_CLEARCOAT].r, 0.0, 1.0);
    s.mat.clearcoat_roughness = clamp(m.clearcoat_roughness * texel[SLOT_CLEARCOAT_ROUGHNESS].g, 0.0, 1.0);
    s.mat.transmission = clamp(m.transmission * texel[SLOT_TRANSMISSION].r, 0.0, 1.0);
    vec3 e = m.emission * texel[SLOT_EMISSIVE].rgb;
    bool double_sided = (m.flags & MATERIAL_DOUBLE_SIDED) != 0u;
    s.emission = (s.front || double_sided) ? e : vec3(0.0);
}

// The material of a surface at texture coordinates uv with vertex colour `color`: s.mat and
// s.emission. Shared by triangle hits and the line space's stored hits.
void surface_material(inout Surface s, GpuMaterialLayout m, vec2 uv, vec4 color) {
    vec4 texel[MATERIAL_SLOTS];
    material_texels(m, surface_slots(m) & ~(1u << SLOT_NORMAL), uv, vec2(0.0), vec2(0.0), texel);
    surface_textured(s, m, texel, color);
}

Surface surface_at(TraceRay r, TraceHit h) {
    Surface s;
    uint tri = h.triangle;
    s.triangle = tri;
    vec3 p0 = bvh_tris[3u * tri].xyz, p1 = bvh_tris[3u * tri + 1u].xyz, p2 = bvh_tris[3u * tri + 2u].xyz;
    float w0 = 1.0 - h.u - h.v;
    s.p = w0 * p0 + h.u * p1 + h.v * p2;
    vec3 ng = normalize(cross(p1 - p0, p2 - p0));
    uvec3 idx = uvec3(indices[3u * tri], indices[3u * tri + 1u], indices[3u * tri + 2u]);
    vec3 ns = w0 * vertex_normal(idx.x) + h.u * vertex_normal(idx.y) + h.v * vertex_normal(idx.z);
    ns = dot(ns, ns) > 0.0 ? normalize(ns) : ng;
    vec3 nc = ns;
    GpuMaterialLayout m = materials[tri_materials[tri]];
    vec2 uv = vec2(0.0);
    bool textured = m.base_color_texture != NO_TEXTURE || m.metallic_roughness_texture != NO_TEXTURE || m.normal_texture != NO_TEXTURE
        || m.emissive_texture != NO_TEXTURE || m.occlusion_texture != NO_TEXTURE || m.clearcoat_texture != NO_TEXTURE
        || m.clearcoat_roughness_texture != NO_TEXTURE || m.transmission_texture != NO_TEXTURE;
    if (textured) {
        uv = triangle_uv(tri, h.u, h.v);
    }
    // Every texture of the hit through one sampling call (see material_texels).
    vec4 texel[MATERIAL_SLOTS];
    material_texels(m, surface_slots(m), uv, vec2(0.0), vec2(0.0), texel);
    if (m.normal_texture != NO_TEXTURE) {
        // Tangent frame of the triangle's texture mapping (glTF: v runs down the image, the
        // map's green axis up, hence the minus on the bitangent).
        vec2 t0 = vertex_uv(idx.x), t1 = vertex_uv(idx.y), t2 = vertex_uv(idx.z);
        vec3 e1 = p1 - p0, e2 = p2 - p0;
        vec2 d1 = t1 - t0, d2 = t2 - t0;
        float det = d1.x * d2.y - d1.y * d2.x;
        if (abs(det) > 1e-20) {
            vec3 tangent = (e1 * d2.y - e2 * d1.y) / det;
            vec3 bitangent = (e2 * d1.x - e1 * d2.x) / det;
            tangent = normalize(tangent - ns * dot(ns, tangent));
            bitangent = cross(ns, tangent) * (dot(cross(ns, tangent), bitangent) < 0.0 ? -1.0 : 1.0);
            vec3 mtex = normal_texel(texel[SLOT_NORMAL]);
            vec3 mapped = tangent * mtex.x * m.normal_scale - bitangent * mtex.y * m.normal_scale + ns * mtex.z;
            if (dot(mapped, mapped) > 0.0) {
                ns = normalize(mapped);
            }
        }
    }
    s.front = dot(ng, r.direction) < 0.0;
    if (!s.front) {
        ng = -ng;
        ns = -ns;
        nc = -nc;
    }
    // A shading normal on the far side of the surface would light the wrong hemisphere.
    if (dot(ns, ng) <= 0.0) {
        ns = ng;
    }
    if (dot(nc, ng) <= 0.0) {
        nc = ng;
    }
    s.ng = ng;
    s.ns = ns;
    s.nc = nc;
    surface_textured(s, m, texel, interpolated_color(idx, h.u, h.v));
    return s;
}

// The closest surface along r through the BVH: true and the surface, or false on a miss.
bool trace_surface(TraceRay r, out Surface s) {
    TraceHit h = trace(r, false);
    if (h.t == NO_HIT) {
        return false;
    }
    s = surface_at(r, h);
    return true;
}

// ---------------------------------------------------------------- BRDF sampling
// The clear coat (KHR_materials_clearcoat's `fresnel_coat`): a GGX lobe of the coat's roughness
// about its normal nc, of weight w = clearcoat · Fc with Fc the Schlick Fresnel of an index of
// refraction of 1.5 at the view direction (F0 0.04), over the base, which keeps 1 − w:
// f_cos = (1 − w) f_base (ns·wi) + w D_c Vis_c (nc·wi).
float coat_weight(Surface s, vec3 wo) {
    return coat_weight(s.mat.clearcoat, clamp(dot(s.nc, wo), 0.0, 1.0));
}

// The coat's GGX lobe times nc·wi (no Fresnel: it is in the weight).
float coat_cos(Surface s, vec3 wo, vec3 wi) {
    float n_l = dot(s.nc, wi);
    float n_v = dot(s.nc, wo);
    if (n_l <= 0.0 || n_v <= 0.0) {
        return 0.0;
    }
    return coat_lobe(s.mat.clearcoat_roughness, max(dot(s.nc, normalize(wo + wi)), 0.0), n_v, n_l) * n_l;
}

// wi mirrored through the surface's tangent plane (about the shading normal): a thin wall's
// transmitted direction as the reflected one it mirrors.
vec3 mirrored(Surface s, vec3 wi) {
    return wi - 2.0 * dot(s.ns, wi) * s.ns;
}

// The base's f · |ns·wi| for wi above the surface (reflection) or, where the material transmits,
// below it (KHR_materials_transmission, thin-walled): with F the Schlick Fresnel at the half
// vector h of wo and wi (of wo and wi mirrored for transmission), t the transmission, m the
// metalness, the reflection is (1 − F)(1 − m)(1 − t) base / π + F D Vis and the transmission
// (1 − F)(1 − m) t base D Vis: the specular lobe mirrored through the surface, tinted by the base
// colour, its light taken from the diffuse part (FORMAT.md, "Transmission").
vec3 base_brdf_cos(Surface s, vec3 wo, vec3 wi) {
    float n_l = dot(s.ns, wi);
    float n_v = dot(s.ns, wo);
    // The side wi leaves by is the geometric surface's; where the shading normal puts wi on the
    // other side, nothing (as `base_pdf`, which samples neither there): a transmitting surface
    // would otherwise reflect light from behind it, or transmit light from in front.
    bool through = dot(s.ng, wi) < 0.0;
    if (through != (n_l < 0.0)) {
        return vec3(0.0);
    }
    if (through) {
        if (s.mat.transmission <= 0.0 || s.mat.diffuse_only) {
            return vec3(0.0);
        }
        wi = mirrored(s, wi);
        n_l = -n_l;
    }
    if (n_l <= 0.0 || n_v <= 0.0) {
        return vec3(0.0);
    }
    if (s.mat.diffuse_only) {
        return lambert(s.mat.base) * n_l;
    }
    if (through) {
        return transmitted_lobe(s.mat, s.ns, wo, wi, n_l, n_v) * n_l;
    }
    vec3 h = normalize(wo + wi);
    float a = ggx_alpha(s.mat.roughness);
    float a2 = a * a;
    float d = ggx_d(max(dot(s.ns, h), 0.0), a2);
    float vis = smith_visibility(n_l, n_v, a2);
    vec3 f = fresnel_schlick(fresnel_f0(s.mat), fresnel_f90(s.mat), max(dot(wo, h), 0.0));
    // Lambert's base / π, divided after the weights (not lambert(base) times them): the order the
    // reference images were made with; it rounds differently.
    return ((1.0 - f) * (1.0 - s.mat.metallic) * (1.0 - s.mat.transmission) * s.mat.base / PI + f * d * vis) * n_l;
}

// The side of a surface of geometric normal ng that the direction w leaves by (for the offset of
// a ray along w): ng, or −ng for light passing through a transmitting surface.
vec3 facing(vec3 ng, vec3 w) {
    return dot(ng, w) < 0.0 ? -ng : ng;
}

// f(wo, wi) · |n·wi|: zero below the geometric surface unless the material transmits.
vec3 brdf_cos(Surface s, vec3 wo, vec3 wi) {
    float g = dot(s.ng, wi);
    if (g == 0.0 || (g < 0.0 && s.mat.transmission <= 0.0)) {
        return vec3(0.0);
    }
    vec3 base = base_brdf_cos(s, wo, wi);
    if (s.mat.clearcoat <= 0.0) {
        return base;
    }
    float w = coat_weight(s, wo);
    // Below the surface the coat only dims what passes through it.
    return base * (1.0 - w) + (g > 0.0 ? w * coat_cos(s, wo, wi) : 0.0);
}

// The luminance of the base's Fresnel reflectance towards wo.
float base_fresnel(Surface s, vec3 wo) {
    return luminance(fresnel_schlick(fresnel_f0(s.mat), fresnel_f90(s.mat), clamp(dot(s.ns, wo), 0.0, 1.0)));
}

// Probability of choosing the specular lobe (of the base's two).
float specular_probability(Surface s, vec3 wo) {
    if (s.mat.diffuse_only) {
        return 0.0;
    }
    float fresnel = base_fresnel(s, wo);
    float diffuse = luminance(s.mat.base) * (1.0 - s.mat.metallic) * (1.0 - fresnel);
    return clamp(fresnel / max(fresnel + diffuse, 1e-6), 0.05, 0.95);
}

// Probability of sampling the clear coat's lobe (else the base's): its weight against the base's
// reflectance estimate, at least 0.1 (a sharp coat highlight is rare under the base's lobes) and
// at most 0.9; 0 without a coat.
float coat_probability(Surface s, vec3 wo) {
    if (s.mat.clearcoat <= 0.0) {
        return 0.0;
    }
    float w = coat_weight(s, wo);
    float base = base_fresnel(s, wo) + luminance(s.mat.base) * (1.0 - s.mat.metallic);
    return clamp(w / max(w + (1.0 - w) * base, 1e-6), 0.1, 0.9);
}

mat3 basis(vec3 n) {
    vec3 t = abs(n.z) < 0.999 ? normalize(cross(vec3(0.0, 0.0, 1.0), n)) : normalize(cross(vec3(1.0, 0.0, 0.0), n));
    return mat3(t, cross(n, t), n);
}

// Density of reflecting wo into wi about a GGX visible normal of perceptual roughness `roughness`
// around n (`sample_ggx_reflection`).
float ggx_reflection_pdf(vec3 n, float roughness, vec3 wo, vec3 wi) {
    float n_v = max(dot(n, wo), 1e-6);
    vec3 h = normalize(wo + wi);
    float a = ggx_alpha(roughness);
    float a2 = a * a;
    return smith_g1(n_v, a2) * ggx_d(max(dot(n, h), 0.0), a2) / (4.0 * n_v);
}

// Probability of transmitting (of the base's non-specular choice; the rest is diffuse): the
// transmission t, as the two share (1 − F)(1 − m) base in the proportions t and 1 − t.
float transmission_probability(Surface s) {
    return s.mat.diffuse_only ? 0.0 : s.mat.transmission;
}

// Density of the base's lobes (diffuse, GGX reflection and its mirror image, the transmission)
// at wi.
float base_pdf(Surface s, vec3 wo, vec3 wi) {
    float n_l = dot(s.ns, wi);
    float g = dot(s.ng, wi);
    float pt = transmission_probability(s);
    float ps = specular_probability(s, wo);
    if (n_l < 0.0 && g < 0.0 && pt > 0.0) {
        return (1.0 - ps) * pt * ggx_reflection_pdf(s.ns, s.mat.roughness, wo, mirrored(s, wi));
    }
    if (n_l <= 0.0 || g <= 0.0) {
        return 0.0;
    }
    float diffuse = n_l / PI;
    if (ps == 0.0) {
        return diffuse;
    }
    return ps * ggx_reflection_pdf(s.ns, s.mat.roughness, wo, wi) + (1.0 - ps) * (1.0 - pt) * diffuse;
}

// Solid-angle density of sampling wi with `sample_brdf`.
float brdf_pdf(Surface s, vec3 wo, vec3 wi) {
    float pc = coat_probability(s, wo);
    if (pc == 0.0) {
        return base_pdf(s, wo, wi);
    }
    bool above = dot(s.nc, wi) > 0.0 && dot(s.ng, wi) > 0.0;
    float coat = above ? ggx_reflection_pdf(s.nc, s.mat.clearcoat_roughness, wo, wi) : 0.0;
    return pc * coat + (1.0 - pc) * base_pdf(s, wo, wi);
}

// GGX visible-normal sampling (Heitz 2018) in the local frame where the normal is +z.
vec3 sample_vndf(vec3 v, float a, vec2 xi) {
    vec3 vh = normalize(vec3(a * v.x, a * v.y, v.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(xi.x);
    float phi = 2.0 * PI * xi.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(a * nh.x, a * nh.y, max(nh.z, 0.0)));
}

// wo reflected about a GGX visible normal of perceptual roughness `roughness` sampled with `xi`
// in the frame `f` (normal f[2]).
vec3 sample_ggx_reflection(mat3 f, float roughness, vec3 wo, vec2 xi) {
    return reflect(-wo, f * sample_vndf(transpose(f) * wo, ggx_alpha(roughness), xi));
}

// `w` where it lies on its lobe's side of the surface (above the geometric normal and the
// lobe's normal n for reflection, below both for transmission), else the zero direction, which
// every BRDF and density gives 0: `brdf_pdf` counts each lobe's density on its own side only,
// so that a reflection sampled below a transmitting surface is not taken for a transmission.
vec3 on_side(Surface s, vec3 n, vec3 w, bool through) {
    float k = through ? -1.0 : 1.0;
    return k * dot(n, w) > 0.0 && k * dot(s.ng, w) > 0.0 ? w : vec3(0.0);
}

// A direction sampled with density `brdf_pdf` (or the zero direction, see `on_side`);
// `specular`: it came from a GGX lobe (rather than the cosine-weighted diffuse one).
vec3 sample_brdf_lobe(Surface s, vec3 wo, out bool specular) {
    float pc = coat_probability(s, wo);
    if (pc > 0.0 && rnd() < pc) {
        specular = true;
        vec2 xi = vec2(rnd(), rnd());
        return on_side(s, s.nc, sample_ggx_reflection(basis(s.nc), s.mat.clearcoat_roughness, wo, xi), false);
    }
    mat3 f = basis(s.ns);
    float ps = specular_probability(s, wo);
    vec2 xi = vec2(rnd(), rnd());
    specular = rnd() < ps;
    if (specular) {
        return on_side(s, s.ns, sample_ggx_reflection(f, s.mat.roughness, wo, xi), false);
    }
    float pt = transmission_probability(s);
    // Transmitting materials draw one more number; opaque ones the same numbers as before.
    if (pt > 0.0 && rnd() < pt) {
        specular = true;
        return on_side(s, s.ns, mirrored(s, sample_ggx_reflection(f, s.mat.roughness, wo, xi)), true);
    }
    float r = sqrt(xi.x);
    float phi = 2.0 * PI * xi.y;
    return on_side(s, s.ns, f * vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - xi.x))), false);
}

vec3 sample_brdf(Surface s, vec3 wo) {
    bool specular;
    return sample_brdf_lobe(s, wo, specular);
}

// Whether something blocks the segment from `o`, a ray origin already offset off its surface,
// to `to`. The length is measured from the offset origin: measured from the surface point, a
// segment to a point on an emissive triangle reached that triangle (and was blocked by it)
// wherever the offset exceeded the 1e-5 relative margin, e.g. on surfaces facing the emitter at
// coordinates >= 0.5 from the origin. Emitter points are offset off their own surface towards
// the origin by the caller.
bool occluded_from(vec3 o, vec3 to) {
    vec3 d = to - o;
    float dist = length(d);
    if (!(dist > 0.0)) {
        return false;
    }
    TraceRay r = make_ray(o, d / dist, 0.0, dist * (1.0 - 1e-5));
    return trace(r, true).t != NO_HIT;
}

// `occluded_from` for the point `from` on a surface of geometric normal `n` (the side the
// segment leaves by).
bool occluded(vec3 from, vec3 n, vec3 to) {
    return occluded_from(offset_ray_origin(from, n), to);
}

// Whether something blocks the unbounded ray from the offset origin `o` along `dir`.
bool occluded_ray_from(vec3 o, vec3 dir) {
    return trace(make_ray(o, dir, 0.0, 3.4e38), true).t != NO_HIT;
}

// `occluded_ray_from` for the point `from` on a surface of geometric normal `n`.
bool occluded_ray(vec3 from, vec3 n, vec3 dir) {
    return occluded_ray_from(offset_ray_origin(from, n), dir);
}

#endif
