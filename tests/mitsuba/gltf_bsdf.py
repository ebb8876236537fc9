"""glTF's metallic-roughness BSDF as kiln defines it, written for Mitsuba 3 (a Python plugin,
registered as "kiln_gltf"), so that Mitsuba's own path tracer integrates exactly the material
kiln's reference path tracer claims to render. Written from the definitions (FORMAT.md,
"Materials"; the glTF specification and its KHR_materials_specular, _ior, _clearcoat and
_transmission extensions), not from kiln's shaders:

    l above:  f(v, l) · cos = [ (1 − F)(1 − metallic)(1 − t) base / π + F · D · Vis ] (ns·l) · (1 − c · Fc)
                            + c · Fc · Dc · Visc · (nc·l)
    l below:  f(v, l) · |cos| = (1 − F)(1 − metallic) t base · D · Vis · |ns·l| · (1 − c · Fc)

- F = F0 + (F90 − F0)(1 − v·h)⁵ (Schlick) with F0 = mix(dielectric F0, base, metallic) and
  F90 = mix(dielectric F90, 1, metallic); the dielectric's F0 and F90 are glTF's core 0.04 and 1
  unless KHR_materials_specular/ior set them.
- D: GGX with α = max(roughness², 10⁻³); Vis: the height-correlated Smith visibility
  G2 / (4 (n·l)(n·v)).
- The clear coat (KHR_materials_clearcoat): c = clearcoat factor × its texture's R,
  Fc = 0.04 + 0.96 (1 − nc·v)⁵ (an index of refraction of 1.5, the Fresnel of the view direction
  to the coat's normal, as the extension's `fresnel_coat` defines it), Dc and Visc GGX and Smith
  of α = (clearcoat roughness × its texture's G)². The coat's normal nc is the interpolated one.
- Transmission (KHR_materials_transmission, thin-walled: no KHR_materials_volume): t = the
  transmission factor × its texture's R. Light below the surface (l on the far side of both the
  geometric and the shading normal) passes through the specular lobe mirrored through the
  surface: D, Vis and F are those of the reflection towards l' = l − 2 (ns·l) ns, the half vector
  that of v and l'; the transmitted light takes the share t of what the diffuse part had.
- Textures (optional, `.npy` arrays of RGBA8 texels, rows top to bottom, read at the mesh's uv
  with v down the image, bilinear on the linear values): the base colour (sRGB) multiplies the
  base colour factor, the metallic-roughness texture's B and G the factors, the normal map
  (x, y from R, G; z = sqrt(1 − x² − y²), x, y scaled by the normal scale) perturbs the
  interpolated normal in the frame of the triangle's texture mapping (tangent along ∂p/∂u, the
  bitangent along ∂p/∂v made orthonormal; glTF's green axis points up the image, against ∂p/∂v).
- Both sides reflect (kiln faces a surface towards the ray it meets): the geometric, shading and
  coat normals are turned to the side the view direction is on; a shading normal then below the
  surface is replaced by the geometric one; nothing reflects below the geometric surface.

Sampling is Mitsuba's own: a cosine-weighted hemisphere and Mitsuba's GGX visible-normal
sampling (`MicrofacetDistribution`), its reflection mirrored through the surface for the
transmission, one lobe chosen uniformly; the density is the mixture's.
"""

import drjit as dr
import mitsuba as mi
import numpy as np

INV_PI = 1.0 / dr.pi


def _ggx_d(n_h, a2):
    d = n_h * n_h * (a2 - 1.0) + 1.0
    return a2 / (dr.pi * d * d)


def _visibility(n_l, n_v, a2):
    return 0.5 / (n_l * dr.sqrt(n_v * n_v * (1.0 - a2) + a2) + n_v * dr.sqrt(n_l * n_l * (1.0 - a2) + a2))


def _alpha(roughness):
    return dr.maximum(roughness * roughness, 1e-3)


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def texture(path, srgb, wrap, linear, scale=(1.0, 1.0, 1.0)):
    """A Mitsuba bitmap texture of the RGB channels of an RGBA8 `.npy` (sRGB decoded here),
    times `scale` per channel (an emissive factor)."""
    texels = np.load(path)[..., :3].astype(np.float32) / 255.0
    if srgb:
        texels = srgb_to_linear(texels).astype(np.float32)
    texels = (texels * np.asarray(scale, dtype=np.float32)).astype(np.float32)
    return mi.load_dict({
        "type": "bitmap",
        "bitmap": mi.Bitmap(np.ascontiguousarray(texels)),
        "raw": True,
        "filter_type": "bilinear" if linear else "nearest",
        "wrap_mode": wrap,
    })


class GltfBsdf(mi.BSDF):
    def __init__(self, props):
        mi.BSDF.__init__(self, props)
        get = lambda name, default: float(props.get(name, default))
        self.base = mi.Color3f(get("base_r", 1.0), get("base_g", 1.0), get("base_b", 1.0))
        self.metallic = get("metallic", 1.0)
        self.roughness = get("roughness", 1.0)
        self.f0 = mi.Color3f(get("f0_r", 0.04), get("f0_g", 0.04), get("f0_b", 0.04))
        self.f90 = get("f90", 1.0)
        self.clearcoat = get("clearcoat", 0.0)
        self.coat_roughness = get("clearcoat_roughness", 0.0)
        self.normal_scale = get("normal_scale", 1.0)
        self.transmission = get("transmission", 0.0)
        wrap = str(props.get("wrap", "repeat"))
        linear = bool(props.get("linear", True))
        tex = lambda name, srgb: (
            texture(str(props.get(name)), srgb, wrap, linear) if props.has_property(name) else None
        )
        self.base_tex = tex("base_tex", True)
        self.mr_tex = tex("metallic_roughness_tex", False)
        self.normal_tex = tex("normal_tex", False)
        self.coat_tex = tex("clearcoat_tex", False)
        self.coat_roughness_tex = tex("clearcoat_roughness_tex", False)
        self.transmission_tex = tex("transmission_tex", False)
        self.lobes = 2 + (self.clearcoat > 0.0) + (self.transmission > 0.0)
        flags = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.GlossyReflection
        if self.transmission > 0.0:
            flags = flags | mi.BSDFFlags.GlossyTransmission
        self.m_flags = flags | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
        self.m_components = [self.m_flags]

    def _surface(self, si):
        """The material and normals at `si`, turned to the side of the view direction:
        (base, metallic, roughness, clearcoat, coat roughness, ng, ns, nc, wi, transmission) in
        world space."""
        wi = si.to_world(si.wi)
        n = dr.normalize(si.sh_frame.n)
        ns = n
        if self.normal_tex is not None:
            t = si.dp_du - n * dr.dot(n, si.dp_du)
            t = dr.normalize(t)
            c = dr.cross(n, t)
            b = c * dr.select(dr.dot(c, si.dp_dv) < 0.0, -1.0, 1.0)
            rgb = self.normal_tex.eval(si)
            x, y = rgb.x * 2.0 - 1.0, rgb.y * 2.0 - 1.0
            z = dr.sqrt(dr.maximum(1.0 - x * x - y * y, 0.0))
            mapped = t * (x * self.normal_scale) - b * (y * self.normal_scale) + n * z
            ok = (dr.squared_norm(mapped) > 0.0) & (dr.squared_norm(si.dp_du) > 0.0)
            ns = dr.select(ok, dr.normalize(mapped), n)
        ng = si.n
        flip = dr.select(dr.dot(ng, wi) < 0.0, -1.0, 1.0)
        ng, ns, nc = ng * flip, ns * flip, n * flip
        ns = dr.select(dr.dot(ns, ng) <= 0.0, ng, ns)
        nc = dr.select(dr.dot(nc, ng) <= 0.0, ng, nc)
        base = self.base * (self.base_tex.eval(si) if self.base_tex is not None else 1.0)
        metallic, roughness = mi.Float(self.metallic), mi.Float(self.roughness)
        if self.mr_tex is not None:
            mr = self.mr_tex.eval(si)
            metallic, roughness = metallic * mr.z, roughness * mr.y
        coat, coat_roughness = mi.Float(self.clearcoat), mi.Float(self.coat_roughness)
        if self.coat_tex is not None:
            coat = coat * self.coat_tex.eval(si).x
        if self.coat_roughness_tex is not None:
            coat_roughness = coat_roughness * self.coat_roughness_tex.eval(si).y
        transmission = mi.Float(self.transmission)
        if self.transmission_tex is not None:
            transmission = transmission * self.transmission_tex.eval(si).x
        clamp = lambda v: dr.clip(v, 0.0, 1.0)
        return (
            base, clamp(metallic), clamp(roughness), clamp(coat), clamp(coat_roughness), ng, ns, nc, wi,
            clamp(transmission),
        )

    def _eval(self, s, wo):
        base, metallic, roughness, coat, coat_roughness, ng, ns, nc, wi, t = s
        below = (dr.dot(ng, wo) < 0.0) & (dr.dot(ns, wo) < 0.0)
        if self.transmission > 0.0:
            # The transmitted direction as the reflection it mirrors.
            wo = dr.select(below, wo - 2.0 * dr.dot(ns, wo) * ns, wo)
        else:
            below = mi.Bool(False)
        n_v, n_l = dr.dot(ns, wi), dr.dot(ns, wo)
        h = dr.normalize(wi + wo)
        a = _alpha(roughness)
        a2 = a * a
        f0 = dr.lerp(self.f0, base, metallic)
        f90 = dr.lerp(self.f90, 1.0, metallic)
        fresnel = f0 + (f90 - f0) * dr.power(1.0 - dr.maximum(dr.dot(wi, h), 0.0), 5.0)
        lobe = _ggx_d(dr.maximum(dr.dot(ns, h), 0.0), a2) * _visibility(n_l, n_v, a2)
        reflected = ((1.0 - fresnel) * (1.0 - metallic) * (1.0 - t) * base * INV_PI + fresnel * lobe) * n_l
        transmitted = (1.0 - fresnel) * (1.0 - metallic) * t * base * lobe * n_l
        value = dr.select(below, transmitted, reflected)
        value = dr.select((n_v > 0.0) & (n_l > 0.0), value, 0.0)
        if self.clearcoat > 0.0:
            c_v, c_l = dr.dot(nc, wi), dr.dot(nc, wo)
            c2 = _alpha(coat_roughness) ** 2
            w = coat * (0.04 + 0.96 * dr.power(1.0 - dr.clip(c_v, 0.0, 1.0), 5.0))
            layer = _ggx_d(dr.maximum(dr.dot(nc, h), 0.0), c2) * _visibility(c_l, c_v, c2) * c_l
            value = value * (1.0 - w) + w * dr.select((c_v > 0.0) & (c_l > 0.0) & ~below, layer, 0.0)
        return dr.select((dr.dot(ng, wo) > 0.0) | below, value, 0.0)

    def _lobes(self, s):
        """The lobes: (normal, alpha or None for the cosine lobe, mirrored through the surface)."""
        _, _, roughness, _, coat_roughness, _, ns, nc, _, _ = s
        lobes = [(ns, None, False), (ns, _alpha(roughness), False)]
        if self.clearcoat > 0.0:
            lobes.append((nc, _alpha(coat_roughness), False))
        if self.transmission > 0.0:
            lobes.append((ns, _alpha(roughness), True))
        return lobes

    def _pdf(self, s, wo):
        ng, wi = s[5], s[8]
        pdf = mi.Float(0.0)
        for n, alpha, mirror in self._lobes(s):
            frame = mi.Frame3f(n)
            side = dr.dot(ng, wo) < 0.0 if mirror else dr.dot(ng, wo) > 0.0
            w = wo - 2.0 * dr.dot(n, wo) * n if mirror else wo
            if alpha is None:
                p = dr.maximum(mi.warp.square_to_cosine_hemisphere_pdf(frame.to_local(w)), 0.0)
            else:
                h = dr.normalize(wi + w)
                distr = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, alpha, True)
                jacobian = 1.0 / (4.0 * dr.maximum(dr.dot(w, h), 1e-12))
                ok = (dr.dot(n, wi) > 0.0) & (dr.dot(n, w) > 0.0)
                if mirror:
                    ok = ok & (dr.dot(n, wo) < 0.0)
                p = dr.select(ok, distr.pdf(frame.to_local(wi), frame.to_local(h)) * jacobian, 0.0)
            pdf += dr.select(side, p, 0.0)
        return pdf / self.lobes

    def sample(self, ctx, si, sample1, sample2, active=True):
        s = self._surface(si)
        wi = s[8]
        lobe = dr.minimum(mi.UInt32(sample1 * self.lobes), self.lobes - 1)
        wo = mi.Vector3f(0.0)
        # A sample outside its own lobe's side (a reflection below the surface, a transmission
        # above it) counts nothing: each lobe's density in `_pdf` is that of its side alone.
        valid = mi.Bool(False)
        ng = s[5]
        for k, (n, alpha, mirror) in enumerate(self._lobes(s)):
            frame = mi.Frame3f(n)
            if alpha is None:
                local = mi.warp.square_to_cosine_hemisphere(sample2)
            else:
                distr = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, alpha, True)
                m, _ = distr.sample(frame.to_local(wi), sample2)
                local = mi.reflect(frame.to_local(wi), m)
                if mirror:
                    local = mi.Vector3f(local.x, local.y, -local.z)
            w = frame.to_world(local)
            side = (local.z < 0.0) & (dr.dot(ng, w) < 0.0) if mirror else (local.z > 0.0) & (dr.dot(ng, w) > 0.0)
            wo = dr.select(lobe == k, w, wo)
            valid = dr.select(lobe == k, side, valid)
        pdf = self._pdf(s, wo)
        value = self._eval(s, wo)
        bs = dr.zeros(mi.BSDFSample3f)
        bs.wo = si.to_local(wo)
        bs.pdf = pdf
        bs.eta = 1.0
        through = dr.dot(s[5], wo) < 0.0
        bs.sampled_type = dr.select(
            through, mi.UInt32(+mi.BSDFFlags.GlossyTransmission), mi.UInt32(+mi.BSDFFlags.GlossyReflection)
        )
        bs.sampled_component = mi.UInt32(0)
        ok = active & valid & (pdf > 0.0)
        return bs, dr.select(ok, value / dr.maximum(pdf, 1e-30), 0.0)

    def eval(self, ctx, si, wo, active=True):
        s = self._surface(si)
        return self._eval(s, si.to_world(wo))

    def pdf(self, ctx, si, wo, active=True):
        s = self._surface(si)
        return self._pdf(s, si.to_world(wo))

    def eval_pdf(self, ctx, si, wo, active=True):
        s = self._surface(si)
        w = si.to_world(wo)
        return self._eval(s, w), self._pdf(s, w)

    def to_string(self):
        return "GltfBsdf[]"


def register():
    mi.register_bsdf("kiln_gltf", lambda props: GltfBsdf(props))
