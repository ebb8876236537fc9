"""glTF's metallic-roughness BSDF as kiln defines it, written for Mitsuba 3 (a Python plugin,
registered as "kiln_gltf"), so that Mitsuba's own path tracer integrates exactly the material
kiln's reference path tracer claims to render. Written from the definitions (FORMAT.md,
"Materials"; the glTF specification and its KHR_materials_specular, _ior and _clearcoat
extensions), not from kiln's shaders:

    f(v, l) · (n·l) = [ (1 − F)(1 − metallic) base / π + F · D · Vis ] (n·l) · (1 − c · Fc)
                    + c · Fc · Dc · Visc · (n·l)

- F = F0 + (F90 − F0)(1 − v·h)⁵ (Schlick) with F0 = mix(dielectric F0, base, metallic) and
  F90 = mix(dielectric F90, 1, metallic); the dielectric's F0 and F90 are glTF's core 0.04 and 1
  unless KHR_materials_specular/ior set them.
- D: GGX with α = max(roughness², 10⁻³); Vis: the height-correlated Smith visibility
  G2 / (4 (n·l)(n·v)).
- The clear coat (KHR_materials_clearcoat): c = clearcoat factor, Fc = 0.04 + 0.96 (1 − n·v)⁵
  (an index of refraction of 1.5, the Fresnel of the view direction to the coat's normal, as the
  extension's `fresnel_coat` defines it), Dc and Visc GGX and Smith of α = clearcoat roughness².
  The coat's normal is the surface's (these test scenes have no normal maps).
- Both sides reflect (kiln faces a surface towards the ray it meets): directions below the
  shading frame are mirrored to the upper side when v is below it.

Sampling is Mitsuba's own: a cosine-weighted hemisphere and Mitsuba's GGX visible-normal
sampling (`MicrofacetDistribution`), one lobe chosen uniformly; the density is the mixture's.
"""

import drjit as dr
import mitsuba as mi

INV_PI = 1.0 / dr.pi


def _ggx_d(n_h, a2):
    d = n_h * n_h * (a2 - 1.0) + 1.0
    return a2 / (dr.pi * d * d)


def _visibility(n_l, n_v, a2):
    return 0.5 / (n_l * dr.sqrt(n_v * n_v * (1.0 - a2) + a2) + n_v * dr.sqrt(n_l * n_l * (1.0 - a2) + a2))


def _alpha(roughness):
    return max(roughness * roughness, 1e-3)


class GltfBsdf(mi.BSDF):
    def __init__(self, props):
        mi.BSDF.__init__(self, props)
        get = lambda name, default: float(props.get(name, default))
        self.base = mi.Color3f(get("base_r", 1.0), get("base_g", 1.0), get("base_b", 1.0))
        self.metallic = get("metallic", 1.0)
        self.alpha = _alpha(get("roughness", 1.0))
        self.f0 = mi.Color3f(get("f0_r", 0.04), get("f0_g", 0.04), get("f0_b", 0.04))
        self.f90 = get("f90", 1.0)
        self.clearcoat = get("clearcoat", 0.0)
        self.coat_alpha = _alpha(get("clearcoat_roughness", 0.0))
        self.lobes = 3 if self.clearcoat > 0.0 else 2
        flags = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.GlossyReflection
        self.m_flags = flags | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
        self.m_components = [self.m_flags]

    def _upper(self, si, wo):
        """wi and wo mirrored to the upper side when wi is below it (two-sided)."""
        wi = mi.Vector3f(si.wi)
        below = mi.Frame3f.cos_theta(wi) < 0.0
        flip = dr.select(below, -1.0, 1.0)
        return mi.Vector3f(wi.x, wi.y, wi.z * flip), mi.Vector3f(wo.x, wo.y, wo.z * flip)

    def _eval(self, wi, wo):
        n_v, n_l = mi.Frame3f.cos_theta(wi), mi.Frame3f.cos_theta(wo)
        valid = (n_v > 0.0) & (n_l > 0.0)
        h = dr.normalize(wi + wo)
        n_h, v_h = dr.maximum(h.z, 0.0), dr.maximum(dr.dot(wi, h), 0.0)
        a2 = self.alpha * self.alpha
        f0 = dr.lerp(self.f0, self.base, self.metallic)
        f90 = dr.lerp(self.f90, 1.0, self.metallic)
        fresnel = f0 + (f90 - f0) * dr.power(1.0 - v_h, 5.0)
        spec = fresnel * _ggx_d(n_h, a2) * _visibility(n_l, n_v, a2)
        value = ((1.0 - fresnel) * (1.0 - self.metallic) * self.base * INV_PI + spec) * n_l
        if self.clearcoat > 0.0:
            c2 = self.coat_alpha * self.coat_alpha
            w = self.clearcoat * (0.04 + 0.96 * dr.power(1.0 - dr.clip(n_v, 0.0, 1.0), 5.0))
            value = value * (1.0 - w) + w * _ggx_d(n_h, c2) * _visibility(n_l, n_v, c2) * n_l
        return dr.select(valid, value, 0.0)

    def _pdf(self, wi, wo):
        n_v, n_l = mi.Frame3f.cos_theta(wi), mi.Frame3f.cos_theta(wo)
        h = dr.normalize(wi + wo)
        jacobian = 1.0 / (4.0 * dr.maximum(dr.dot(wo, h), 1e-12))
        pdf = mi.warp.square_to_cosine_hemisphere_pdf(wo)
        for alpha in [self.alpha, self.coat_alpha][: self.lobes - 1]:
            distr = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, alpha, True)
            pdf += distr.pdf(wi, h) * jacobian
        return dr.select((n_v > 0.0) & (n_l > 0.0), pdf / self.lobes, 0.0)

    def sample(self, ctx, si, sample1, sample2, active=True):
        wi, _ = self._upper(si, mi.Vector3f(0.0, 0.0, 1.0))
        lobe = dr.minimum(mi.UInt32(sample1 * self.lobes), self.lobes - 1)
        wo = mi.warp.square_to_cosine_hemisphere(sample2)
        for k, alpha in enumerate([self.alpha, self.coat_alpha][: self.lobes - 1]):
            distr = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, alpha, True)
            m, _ = distr.sample(wi, sample2)
            wo = dr.select(lobe == k + 1, mi.reflect(wi, m), wo)
        pdf = self._pdf(wi, wo)
        value = self._eval(wi, wo)
        below = mi.Frame3f.cos_theta(si.wi) < 0.0
        bs = dr.zeros(mi.BSDFSample3f)
        bs.wo = mi.Vector3f(wo.x, wo.y, dr.select(below, -wo.z, wo.z))
        bs.pdf = pdf
        bs.eta = 1.0
        bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
        bs.sampled_component = mi.UInt32(0)
        ok = active & (pdf > 0.0)
        return bs, dr.select(ok, value / dr.maximum(pdf, 1e-30), 0.0)

    def eval(self, ctx, si, wo, active=True):
        wi, wo = self._upper(si, wo)
        return self._eval(wi, wo)

    def pdf(self, ctx, si, wo, active=True):
        wi, wo = self._upper(si, wo)
        return self._pdf(wi, wo)

    def eval_pdf(self, ctx, si, wo, active=True):
        wi, wo = self._upper(si, wo)
        return self._eval(wi, wo), self._pdf(wi, wo)

    def to_string(self):
        return "GltfBsdf[]"


def register():
    mi.register_bsdf("kiln_gltf", lambda props: GltfBsdf(props))
