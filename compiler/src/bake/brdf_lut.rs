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
//! # Quadrature
//!
//! Each integral is a deterministic Gauss–Legendre rule over the half vector h in *stretched*
//! polar coordinates (θ', φ): tan θ_h = α tan θ', the configuration in which the GGX normal
//! distribution becomes the cosine lobe (Heitz 2018), so that D(h) cos θ_h dω_h = cos θ' dω' / π
//! and the sharp peak of D is spread evenly over θ'. The integrand becomes
//!
//!   f₁ (n·l) dl = (1/π) (G₂(v, l) / (n·v)) (α sin²θ' cos φ sin θ_v + sin θ' cos θ' n·v) dθ' dφ,
//!
//! bounded and smooth, also for grazing views. The reflected direction l lies above the horizon
//! exactly when θ_h < θ_max(φ), tan θ_max = (A + sin θ_v cos φ) / n·v with
//! A = √(sin²θ_v cos²φ + (n·v)²), so each azimuth integrates over [0, θ'_max(φ)] and the
//! horizon, where G₂ falls to 0 in a layer as thin as n·v, is an end point of the rule instead of
//! a kink inside it. The polar variable is τ = tan(θ'/2) (sin and cos then cost one division),
//! warped by τ = τ_max (1 − (1 − u)²) to crowd the nodes into that layer. The azimuth (the
//! integrand is even in φ) is split at φ = π/2, where θ_max swings from near π/2 to near 0 for
//! grazing views.
//!
//! 12 polar × 2 × 6 azimuthal nodes (144 evaluations of the integrand per texel, against 2048
//! samples before) give a maximum absolute error of about 1.5 × 10⁻⁴ against the independent f64
//! quadrature of the tests; texels are evaluated eight at a time along n·v in f64 with the same
//! arithmetic in every lane, so the table is the same whatever the thread count or the lane a texel
//! lands in.

use std::sync::{Arc, Mutex};

/// Gauss–Legendre order of the polar (θ') rule.
const POLAR_NODES: usize = 12;

/// Gauss–Legendre order of the azimuthal rule on each of φ ∈ [0, π/2] and [π/2, π].
const AZIMUTH_NODES: usize = 6;

/// Evaluations of the integrand per texel (recorded in the manifest): enough for a maximum
/// absolute error below 10⁻³ against a high-order quadrature at every texel centre checked by the
/// tests (measured: about 1.5 × 10⁻⁴).
pub const SAMPLES: u32 = (POLAR_NODES * 2 * AZIMUTH_NODES) as u32;

/// Texels evaluated together (the inner loops run over them and vectorise).
const LANES: usize = 8;

/// Nodes and weights of the Gauss–Legendre rule of order `n` on [0, 1] (Newton on the Legendre
/// recurrence from the usual cosine guesses; the weights sum to 1).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    (p0, p1) = (p1, p2);
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            (0.5 * (1.0 - x), 1.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// The scene-independent part of the rule.
struct Rule {
    /// Polar nodes: (1 − (1 − u)², its derivative 2 (1 − u) times the Gauss weight).
    polar: [(f64, f64); POLAR_NODES],
    /// Azimuthal nodes: (cos φ, weight in dφ / π), φ ∈ [0, π].
    azimuth: [(f64, f64); 2 * AZIMUTH_NODES],
}

impl Rule {
    fn new() -> Rule {
        let gp = gauss_legendre(POLAR_NODES);
        let ga = gauss_legendre(AZIMUTH_NODES);
        Rule {
            polar: std::array::from_fn(|k| {
                let (u, w) = gp[k];
                (1.0 - (1.0 - u) * (1.0 - u), 2.0 * (1.0 - u) * w)
            }),
            azimuth: std::array::from_fn(|k| {
                let (t, w) = ga[k % AZIMUTH_NODES];
                let half = (k / AZIMUTH_NODES) as f64;
                ((std::f64::consts::FRAC_PI_2 * (half + t)).cos(), 0.5 * w)
            }),
        }
    }

    fn get() -> &'static Rule {
        static RULE: std::sync::OnceLock<Rule> = std::sync::OnceLock::new();
        RULE.get_or_init(Rule::new)
    }
}

/// (R, G) for `LANES` values of n·v (each in (0, 1]) at one perceptual roughness.
fn integrate_lanes(n_v: [f64; LANES], roughness: f64, rule: &Rule) -> [(f64, f64); LANES] {
    let alpha = (roughness * roughness).max(1e-6);
    let a2 = alpha * alpha;
    let cv = n_v;
    let sv = cv.map(|c| (1.0 - c * c).max(0.0).sqrt());
    // √(α² + (1 − α²)(n·v)²), the view's half of the height-correlated G₂.
    let kv = cv.map(|c| (a2 + (1.0 - a2) * c * c).sqrt());
    let (mut r, mut g) = ([0.0; LANES], [0.0; LANES]);
    for &(cp, wp) in &rule.azimuth {
        // tan θ'_max = tan θ_max / α, in the form without cancellation for the sign of cos φ;
        // then τ_max = tan(θ'_max / 2).
        let mut tau_max = [0.0; LANES];
        for k in 0..LANES {
            let (x, c) = (sv[k] * cp, cv[k]);
            let a = (x * x + c * c).sqrt();
            let t = if cp >= 0.0 { (a + x) / c } else { c / (a - x) } / alpha;
            tau_max[k] = t / (1.0 + (1.0 + t * t).sqrt());
        }
        let (mut rp, mut gp) = ([0.0; LANES], [0.0; LANES]);
        for &(warp, wu) in &rule.polar {
            for k in 0..LANES {
                let tau = tau_max[k] * warp;
                let q = 1.0 / (1.0 + tau * tau);
                let (s, c) = (2.0 * tau * q, (1.0 - tau * tau) * q);
                // The unstretched half vector h = (α s cos φ, α s sin φ, c) / len.
                let sx = sv[k] * alpha * s * cp;
                let len = (a2 * s * s + c * c).sqrt();
                let v_h = (sx + cv[k] * c) / len;
                let n_l = (2.0 * v_h * c / len - cv[k]).max(0.0);
                // G₂ / (n·v), which stays finite as n·v → 0.
                let g2 = 2.0 * n_l / (cv[k] * (a2 + (1.0 - a2) * n_l * n_l).sqrt() + n_l * kv[k]);
                // dθ' = 2 q dτ; the measure's sin θ' (α sin θ' cos φ sin θ_v + cos θ' n·v).
                let w = wu * 2.0 * q * g2 * s * (sx + cv[k] * c);
                let m = 1.0 - v_h;
                let fc = m * m * m * m * m;
                rp[k] += (1.0 - fc) * w;
                gp[k] += fc * w;
            }
        }
        for k in 0..LANES {
            // dτ = τ_max d(warp); the φ-symmetry doubles the half-range rule, cancelling the 1/2
            // of 1/π · π.
            r[k] += wp * tau_max[k] * rp[k];
            g[k] += wp * tau_max[k] * gp[k];
        }
    }
    std::array::from_fn(|k| (2.0 * r[k], 2.0 * g[k]))
}

/// (R, G) for one (n·v, perceptual roughness) pair, n·v in (0, 1], by the table's quadrature
/// (the same arithmetic, so the same values as the table at its texel centres).
pub fn integrate(n_v: f64, roughness: f64) -> (f64, f64) {
    integrate_lanes([n_v; LANES], roughness, Rule::get())[0]
}

/// The table: `res × res` texels of (R, G) as unorm16, row j (roughness) after row j − 1, texel i
/// (n·v) within a row. Computed on every call; [`table`] caches it.
pub fn bake(res: u32) -> Vec<[u16; 2]> {
    use rayon::prelude::*;
    let rule = Rule::get();
    let n = res as usize;
    let q = |x: f64| (x.clamp(0.0, 1.0) * 65535.0).round() as u16;
    let mut out = vec![[0u16; 2]; n * n];
    out.par_chunks_mut(n).enumerate().for_each(|(j, row)| {
        let roughness = (j as f64 + 0.5) / res as f64;
        for (c, texels) in row.chunks_mut(LANES).enumerate() {
            // A short last chunk repeats its last n·v in the unused lanes.
            let n_v = std::array::from_fn(|k| ((c * LANES + k).min(n - 1) as f64 + 0.5) / res as f64);
            let rg = integrate_lanes(n_v, roughness, rule);
            for (t, &(r, g)) in texels.iter_mut().zip(&rg) {
                *t = [q(r), q(g)];
            }
        }
    });
    out
}

/// The table at resolution `res`, computed once per process and shared. Concurrent first
/// callers may each compute it (no thread ever waits on another's bake, so a caller inside a
/// rayon pool cannot deadlock); the first result stored is kept, and all are identical.
pub fn table(res: u32) -> Arc<[[u16; 2]]> {
    /// A baked table and its resolution.
    type Cached = (u32, Arc<[[u16; 2]]>);
    static CACHE: Mutex<Vec<Cached>> = Mutex::new(Vec::new());
    let lookup = |cache: &[Cached]| cache.iter().find(|(r, _)| *r == res).map(|(_, t)| t.clone());
    if let Some(t) = lookup(&CACHE.lock().unwrap_or_else(|e| e.into_inner())) {
        return t;
    }
    let baked: Arc<[[u16; 2]]> = bake(res).into();
    let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(t) = lookup(&cache) {
        return t;
    }
    cache.push((res, baked.clone()));
    baked
}

/// The BRDF-table stage. Its hash depends on the resolution and the quadrature alone, not on the
/// scene, so that every file baked with the same settings shares it.
pub fn stage(ctx: &super::BakeContext) -> super::Sections {
    let res = ctx.settings.brdf_lut_res;
    let mut out = super::Sections::default();
    out.push(kiln_format::sections::BRDF_LUT, 0, bytemuck::cast_slice(ctx.lut()).to_vec());
    out.brdf_lut = Some(kiln_format::manifest::BrdfLutInfo { resolution: res, samples: SAMPLES });
    out
}
