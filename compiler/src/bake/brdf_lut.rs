//! The split-sum BRDF lookup table (Karis 2013) for GGX with Smith height-correlated
//! masking-shadowing (Heitz 2014) and α = roughness².
//!
//! Texel (i, j) of an N × N table holds, for n·v = (i + ½)/N and perceptual roughness
//! (j + ½)/N, the two integrals
//!   R = ∫ f₁(l) (1 − F_c) (n·l) dl,   G = ∫ f₁(l) F_c (n·l) dl,   F_c = (1 − v·h)⁵,
//! where f₁ is the specular BRDF with F = 1, so that the pre-integrated specular of a material
//! with reflectance F0 (and F90 = 1) is F0·R + G. R + G is the directional albedo of the specular
//! lobe, which the player uses for multiple-scattering energy compensation.
//!
//! Each integral is estimated by importance sampling the GGX distribution of *visible* normals
//! (Heitz 2018) over a Hammersley point set: with h drawn with density G₁(v) max(0, v·h) D(h) / (n·v),
//! the estimator of ∫ f₁ (n·l) dl is G₂(v, l) / G₁(v), bounded by 1, which keeps grazing views
//! (n·v → 0) as accurate as head-on ones.

/// Hammersley samples per texel: enough for a maximum absolute error below 10⁻³ against
/// a high-order quadrature at every texel centre of the default table (measured by the tests).
pub const SAMPLES: u32 = 2048;

/// Smith Λ of GGX for a direction at cosine `c` to the normal.
fn lambda(alpha2: f64, c: f64) -> f64 {
    let c2 = c * c;
    let tan2 = (1.0 - c2).max(0.0) / c2;
    0.5 * (-1.0 + (1.0 + alpha2 * tan2).sqrt())
}

/// Height-correlated masking-shadowing G₂(v, l).
pub fn g2(alpha2: f64, n_v: f64, n_l: f64) -> f64 {
    1.0 / (1.0 + lambda(alpha2, n_v) + lambda(alpha2, n_l))
}

/// Van der Corput radical inverse in base 2.
fn radical_inverse(i: u32) -> f64 {
    i.reverse_bits() as f64 / 4_294_967_296.0
}

/// A visible normal for view `v` (tangent space, z = normal) and roughness α from the unit
/// square point (u1, u2) (Heitz 2018, "Sampling the GGX Distribution of Visible Normals").
fn visible_normal(v: [f64; 3], alpha: f64, u1: f64, u2: f64) -> [f64; 3] {
    let vh = normalize([alpha * v[0], alpha * v[1], v[2]]);
    let lensq = vh[0] * vh[0] + vh[1] * vh[1];
    let t1 = if lensq > 0.0 { [-vh[1] / lensq.sqrt(), vh[0] / lensq.sqrt(), 0.0] } else { [1.0, 0.0, 0.0] };
    let t2 = cross(vh, t1);
    let r = u1.sqrt();
    let phi = std::f64::consts::TAU * u2;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh[2]);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let p3 = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    let nh: [f64; 3] = std::array::from_fn(|k| p1 * t1[k] + p2 * t2[k] + p3 * vh[k]);
    normalize([alpha * nh[0], alpha * nh[1], nh[2].max(0.0)])
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    if l > 0.0 { a.map(|x| x / l) } else { [0.0, 0.0, 1.0] }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// (R, G) for one (n·v, perceptual roughness) pair, from `samples` Hammersley points.
pub fn integrate(n_v: f64, roughness: f64, samples: u32) -> (f64, f64) {
    let alpha = (roughness * roughness).max(1e-6);
    let alpha2 = alpha * alpha;
    let v = [(1.0 - n_v * n_v).max(0.0).sqrt(), 0.0, n_v];
    let g1_v = 1.0 / (1.0 + lambda(alpha2, n_v));
    let (mut r, mut g) = (0.0, 0.0);
    for i in 0..samples {
        let h = visible_normal(v, alpha, (i as f64 + 0.5) / samples as f64, radical_inverse(i));
        let v_h = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
        let n_l = 2.0 * v_h * h[2] - v[2];
        if n_l <= 0.0 || v_h <= 0.0 {
            continue;
        }
        let w = g2(alpha2, n_v, n_l) / g1_v;
        let fc = (1.0 - v_h).powi(5);
        r += (1.0 - fc) * w;
        g += fc * w;
    }
    (r / samples as f64, g / samples as f64)
}

/// The table: `res × res` texels of (R, G) as unorm16, row j (roughness) after row j − 1, texel i
/// (n·v) within a row.
pub fn bake(res: u32, samples: u32) -> Vec<[u16; 2]> {
    use rayon::prelude::*;
    (0..res * res)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % res, k / res);
            let (r, g) = integrate((i as f64 + 0.5) / res as f64, (j as f64 + 0.5) / res as f64, samples);
            let q = |x: f64| (x.clamp(0.0, 1.0) * 65535.0).round() as u16;
            [q(r), q(g)]
        })
        .collect()
}

/// The BRDF-table stage. Its hash depends on the resolution and sample count alone, not on the
/// scene, so that every file baked with the same settings shares it.
pub fn stage(ctx: &super::BakeContext) -> super::Sections {
    let res = ctx.settings.brdf_lut_res;
    let hash = kiln_format::ContentHasher::new()
        .part("stage", b"brdf-lut")
        .part("algorithm", super::ALGORITHM_VERSION.as_bytes())
        .part("res", &res.to_le_bytes())
        .part("samples", &SAMPLES.to_le_bytes())
        .finish();
    let mut out = super::Sections::default();
    out.push(kiln_format::sections::BRDF_LUT, 0, bytemuck::cast_slice(ctx.lut()).to_vec(), hash);
    out.brdf_lut = Some(kiln_format::manifest::BrdfLutInfo { resolution: res, samples: SAMPLES });
    out
}
