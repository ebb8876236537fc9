//! Preetham, Shirley and Smits's analytic daylight ("A practical analytic model for daylight",
//! SIGGRAPH 1999): the sky's luminance and chromaticity from the sun's position and the
//! atmosphere's turbidity through the Perez et al. distribution, and the sun itself as a
//! directional light of the solar illuminance through the same atmosphere.
//!
//! Units: the model gives luminance in kcd/m²; kiln's radiance is that times the environment's
//! `intensity` (default 1 — a sidecar usually sets something like 0.02 so that a sunlit white
//! surface comes out near 0.5 at exposure 1). The sun's illuminance outside the atmosphere is
//! 128 klux (solar constant × luminous efficacy), dimmed per channel by Rayleigh and aerosol
//! (Ångström) optical depths along Kasten's relative air mass, as the paper's appendix does
//! without its ozone and water-vapour terms; its colour is that transmittance.

use glam::Vec3;
use kiln_format::manifest::{Light, LightKind};

/// The name of the sun's directional light (an environment replaced later removes it).
pub const SUN_NAME: &str = "sun (preetham)";
/// The sidecar's default sun: 45° up, from the −z, +x quadrant.
pub const DEFAULT_SUN: [f32; 3] = [0.5, std::f32::consts::FRAC_1_SQRT_2, -0.5];
/// The sidecar's default turbidity (a clear day).
pub const DEFAULT_TURBIDITY: f32 = 3.0;
/// Solar illuminance outside the atmosphere, klux.
const SOLAR_KLUX: f32 = 128.0;
/// Albedo of the ground below the horizon.
const GROUND_ALBEDO: f32 = 0.2;

/// Perez coefficients A–E as linear functions of turbidity (a·T + b), from the paper's
/// appendix, for luminance Y and chromaticities x and y.
const PEREZ_Y: [[f32; 2]; 5] =
    [[0.1787, -1.4630], [-0.3554, 0.4275], [-0.0227, 5.3251], [0.1206, -2.5771], [-0.0670, 0.3703]];
const PEREZ_X: [[f32; 2]; 5] =
    [[-0.0193, -0.2592], [-0.0665, 0.0008], [-0.0004, 0.2125], [-0.0641, -0.8989], [-0.0033, 0.0452]];
const PEREZ_YC: [[f32; 2]; 5] =
    [[-0.0167, -0.2608], [-0.0950, 0.0092], [-0.0079, 0.2102], [-0.0441, -1.6537], [-0.0109, 0.0529]];
/// Zenith chromaticity: rows T², T, 1 against columns θs³, θs², θs, 1.
const ZENITH_X: [[f32; 4]; 3] = [
    [0.00166, -0.00375, 0.00209, 0.0],
    [-0.02903, 0.06377, -0.03202, 0.00394],
    [0.11693, -0.21196, 0.06052, 0.25886],
];
const ZENITH_Y: [[f32; 4]; 3] = [
    [0.00275, -0.00610, 0.00317, 0.0],
    [-0.04214, 0.08970, -0.04153, 0.00516],
    [0.15346, -0.26756, 0.06670, 0.26688],
];

/// The sky for one sun position and turbidity.
#[derive(Debug, Clone, Copy)]
pub struct Sky {
    sun: Vec3,
    turbidity: f32,
    theta_s: f32,
    /// Perez coefficients of Y, x, y.
    coeffs: [[f32; 5]; 3],
    /// Zenith Y (kcd/m²), x, y over the Perez function at the zenith.
    zenith_scaled: [f32; 3],
}

fn perez(c: &[f32; 5], cos_theta: f32, gamma: f32) -> f32 {
    let [a, b, cc, d, e] = *c;
    (1.0 + a * (b / cos_theta.max(0.01)).exp()) * (1.0 + cc * (d * gamma).exp() + e * gamma.cos().powi(2))
}

impl Sky {
    /// The model for the unit direction towards the sun (normalised here; it must be above the
    /// horizon) and turbidity in [1.7, 10] (the fit's range).
    pub fn new(sun: Vec3, turbidity: f32) -> Result<Sky, String> {
        let sun = sun.normalize_or_zero();
        if !(sun.y > 0.0) {
            return Err("[sky] sun_direction must point above the horizon (y > 0), towards the sun".into());
        }
        if !(1.7..=10.0).contains(&turbidity) {
            return Err(format!("[sky] turbidity {turbidity} is outside the model's range 1.7..=10"));
        }
        let t = turbidity;
        let theta_s = sun.y.clamp(-1.0, 1.0).acos();
        let line = |c: &[[f32; 2]; 5]| c.map(|[a, b]| a * t + b);
        let coeffs = [line(&PEREZ_Y), line(&PEREZ_X), line(&PEREZ_YC)];
        let chi = (4.0 / 9.0 - t / 120.0) * (std::f32::consts::PI - 2.0 * theta_s);
        let zenith_y = (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192;
        let poly = |m: &[[f32; 4]; 3]| {
            let th = [theta_s.powi(3), theta_s.powi(2), theta_s, 1.0];
            let row = |r: &[f32; 4]| r.iter().zip(th).map(|(a, b)| a * b).sum::<f32>();
            t * t * row(&m[0]) + t * row(&m[1]) + row(&m[2])
        };
        let zenith = [zenith_y, poly(&ZENITH_X), poly(&ZENITH_Y)];
        let mut zenith_scaled = [0.0; 3];
        for i in 0..3 {
            zenith_scaled[i] = zenith[i] / perez(&coeffs[i], 1.0, theta_s);
        }
        Ok(Sky { sun, turbidity, theta_s, coeffs, zenith_scaled })
    }

    /// Linear Rec. 709 radiance (kcd/m²) of the sky in unit direction `d` (the horizon's value
    /// below it; the caller replaces that with the ground).
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        let cos_theta = d.y.max(0.0);
        let gamma = d.dot(self.sun).clamp(-1.0, 1.0).acos();
        let v: [f32; 3] =
            std::array::from_fn(|i| self.zenith_scaled[i] * perez(&self.coeffs[i], cos_theta, gamma));
        xyy_to_rgb(v[1], v[2], v[0])
    }

    /// Transmittance of the atmosphere towards the sun at the R, G, B wavelengths.
    fn sun_transmittance(&self) -> Vec3 {
        let deg = self.theta_s.to_degrees();
        let mass = 1.0 / (self.theta_s.cos() + 0.15 * (93.885 - deg).max(1e-3).powf(-1.253));
        let beta = 0.04608 * self.turbidity - 0.04586;
        let tau = |lambda_um: f32| 0.008735 * lambda_um.powf(-4.08) + beta * lambda_um.powf(-1.3);
        Vec3::new((-tau(0.680) * mass).exp(), (-tau(0.550) * mass).exp(), (-tau(0.440) * mass).exp())
    }

    /// The sun as a directional light: illuminance (klux × `intensity`) on a surface facing it,
    /// coloured by the transmittance (normalised to unit luminance).
    pub fn sun_light(&self, intensity: f32) -> Light {
        let t = self.sun_transmittance();
        let lum = kiln_format::gpu::luminance(t.to_array());
        Light {
            name: SUN_NAME.into(),
            kind: LightKind::Directional,
            position: [0.0; 3],
            direction: (-self.sun).to_array(),
            right: [0.0; 3],
            color: (t / lum).to_array(),
            intensity: SOLAR_KLUX * lum * intensity,
            range: 0.0,
            casts_shadows: true,
        }
    }

    /// Radiance of a Lambertian ground of albedo 0.2 lit by the sun and the sky of `pixels` (a
    /// map of `width`, upper half): what the rows below the horizon show.
    pub fn ground(&self, pixels: &[[f32; 3]], width: u32) -> Vec3 {
        let height = width / 2;
        let mut e = Vec3::ZERO;
        for y in 0..height / 2 {
            let (t0, t1) = (
                std::f32::consts::PI * y as f32 / height as f32,
                std::f32::consts::PI * (y + 1) as f32 / height as f32,
            );
            // ∫ cos θ sin θ dθ over the row, times the row's dφ.
            let w = 0.5 * (t1.sin().powi(2) - t0.sin().powi(2)) * std::f32::consts::TAU / width as f32;
            for p in &pixels[(y * width) as usize..((y + 1) * width) as usize] {
                e += Vec3::from(*p) * w;
            }
        }
        e += self.sun_transmittance() * SOLAR_KLUX * self.sun.y;
        e * GROUND_ALBEDO / std::f32::consts::PI
    }
}

/// CIE xyY to linear Rec. 709 RGB (negative components clamp to 0).
fn xyy_to_rgb(x: f32, y: f32, lum: f32) -> Vec3 {
    if !(y > 0.0) {
        return Vec3::ZERO;
    }
    let (cx, cz) = (x * lum / y, (1.0 - x - y) * lum / y);
    Vec3::new(
        3.2406 * cx - 1.5372 * lum - 0.4986 * cz,
        -0.9689 * cx + 1.8758 * lum + 0.0415 * cz,
        0.0557 * cx - 0.2040 * lum + 1.0570 * cz,
    )
    .max(Vec3::ZERO)
}
