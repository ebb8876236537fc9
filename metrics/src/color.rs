//! Colour spaces and FLIP's colour distance, in `f32` with the reference implementation's
//! constants (`FLIP.h`, class `color3`).
//!
//! FLIP filters in YCxCz, an opponent space linear in XYZ (so that filtering is meaningful), and
//! measures colour differences in CIELAB with the Hunt effect applied, under the D65 white point.

/// Linear sRGB to CIE XYZ (D65), written as the exact fractions the reference uses.
const RGB_TO_XYZ: [[f32; 3]; 3] = [
    [10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0],
    [2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0],
    [1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0],
];

/// CIE XYZ (D65) to linear sRGB. The digits are the reference's (more than `f32` holds), kept so
/// that the two read the same.
#[allow(clippy::excessive_precision)]
const XYZ_TO_RGB: [[f32; 3]; 3] = [
    [3.241003275, -1.537398934, -0.498615861],
    [-0.969224334, 1.875930071, 0.041554224],
    [0.055639423, -0.204011202, 1.057148933],
];

/// The D65 white point in XYZ, and its inverse (both with the reference's digits).
#[allow(clippy::excessive_precision)]
const WHITE: [f32; 3] = [0.950428545, 1.0, 1.088900371];
#[allow(clippy::excessive_precision)]
const INV_WHITE: [f32; 3] = [1.052156925, 1.0, 0.918357670];

#[inline(always)]
fn mul(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// Luminance of linear sRGB (Rec. 709 weights).
pub(crate) fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// Clamps to `[0, 1]` the way the reference does (`min(max(v, 0), 1)` written with `>`), which
/// sends NaN to 0: an overflowing tone-mapped value is black there, not NaN.
#[inline(always)]
pub(crate) fn clamp01(v: f32) -> f32 {
    let v = if v > 0.0 { v } else { 0.0 };
    if v > 1.0 { 1.0 } else { v }
}

/// Linear sRGB to YCxCz: like CIELAB but linear in XYZ (Y = 116·Y/Yn − 16 without the cube
/// root), so the contrast sensitivity filters can be applied in it.
pub(crate) fn linear_rgb_to_ycxcz(rgb: [f32; 3]) -> [f32; 3] {
    let xyz = mul(&RGB_TO_XYZ, rgb);
    let [x, y, z] = [xyz[0] * INV_WHITE[0], xyz[1] * INV_WHITE[1], xyz[2] * INV_WHITE[2]];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// YCxCz back to linear sRGB (unclamped).
#[inline(always)]
fn ycxcz_to_linear_rgb(ycxcz: [f32; 3]) -> [f32; 3] {
    let y = (ycxcz[0] + 16.0) / 116.0;
    let cx = ycxcz[1] / 500.0;
    let cz = ycxcz[2] / 200.0;
    let xyz = [(y + cx) * WHITE[0], y * WHITE[1], (y - cz) * WHITE[2]];
    mul(&XYZ_TO_RGB, xyz)
}

/// Linear sRGB to CIELAB (D65).
#[inline(always)]
fn linear_rgb_to_lab(rgb: [f32; 3]) -> [f32; 3] {
    const DELTA: f32 = 6.0 / 29.0;
    const DELTA_CUBE: f32 = DELTA * DELTA * DELTA;
    let factor = 1.0 / (3.0 * DELTA * DELTA);
    let term = 4.0 / 29.0;
    let xyz = mul(&RGB_TO_XYZ, rgb);
    let f = |v: f32, white_inv: f32| {
        let v = v * white_inv;
        if v > DELTA_CUBE { crate::fastmath::cbrt(v) } else { factor * v + term }
    };
    let [fx, fy, fz] = [f(xyz[0], INV_WHITE[0]), f(xyz[1], INV_WHITE[1]), f(xyz[2], INV_WHITE[2])];
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// The Hunt effect (chroma looks stronger at higher luminance): scales a and b by L/100.
#[inline(always)]
fn hunt(lab: [f32; 3]) -> [f32; 3] {
    [lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]]
}

/// HyAB distance (Abasi et al. 2020): city-block in L plus Euclidean in (a, b), which suits large
/// colour differences better than ΔE.
#[inline(always)]
fn hyab(p: [f32; 3], q: [f32; 3]) -> f32 {
    let (da, db) = (p[1] - q[1], p[2] - q[2]);
    (p[0] - q[0]).abs() + (da * da + db * db).sqrt()
}

/// Exponent `q_c` on the HyAB distance (FLIP paper, section 4.2).
const QC: f32 = 0.7;
/// `p_c`, `p_t`: distances below `p_c · c_max` map linearly onto `[0, p_t]`, the rest onto
/// `(p_t, 1]` (the paper's error redistribution, which spends most of the range on the errors
/// that matter).
const PC: f32 = 0.4;
const PT: f32 = 0.95;

/// A filtered YCxCz pixel, clamped to the RGB gamut, in Hunt-adjusted CIELAB.
#[inline(always)]
pub(crate) fn filtered_to_hunt_lab(ycxcz: [f32; 3]) -> [f32; 3] {
    hunt(linear_rgb_to_lab(ycxcz_to_linear_rgb(ycxcz).map(clamp01)))
}

/// Constants of the colour-difference remapping.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ColorScale {
    cmax: f32,
    pccmax: f32,
}

impl ColorScale {
    /// `c_max`: the (exponentiated) distance between pure green and pure blue, the largest HyAB
    /// distance in the gamut after the Hunt adjustment.
    pub(crate) fn new() -> Self {
        let green = hunt(linear_rgb_to_lab([0.0, 1.0, 0.0]));
        let blue = hunt(linear_rgb_to_lab([0.0, 0.0, 1.0]));
        let cmax = hyab(green, blue).powf(QC);
        ColorScale { cmax, pccmax: PC * cmax }
    }

    /// The colour error in `[0, 1]` of two Hunt-adjusted CIELAB pixels.
    #[inline(always)]
    pub(crate) fn error(&self, reference: [f32; 3], test: [f32; 3]) -> f32 {
        let d = crate::fastmath::pow(hyab(reference, test), QC);
        if d < self.pccmax {
            d * (PT / self.pccmax)
        } else {
            PT + ((d - self.pccmax) / (self.cmax - self.pccmax)) * (1.0 - PT)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ycxcz_round_trips() {
        for rgb in [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [0.2, 0.7, 0.1], [0.9, 0.05, 0.6]] {
            let back = ycxcz_to_linear_rgb(linear_rgb_to_ycxcz(rgb));
            for c in 0..3 {
                assert!((back[c] - rgb[c]).abs() < 1e-5, "{rgb:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn white_is_lab_100() {
        let lab = linear_rgb_to_lab([1.0, 1.0, 1.0]);
        assert!((lab[0] - 100.0).abs() < 1e-3 && lab[1].abs() < 1e-2 && lab[2].abs() < 1e-2, "{lab:?}");
    }

    #[test]
    fn color_error_spans_zero_to_one() {
        let s = ColorScale::new();
        let g = hunt(linear_rgb_to_lab([0.0, 1.0, 0.0]));
        let b = hunt(linear_rgb_to_lab([0.0, 0.0, 1.0]));
        assert_eq!(s.error(g, g), 0.0);
        assert!((s.error(g, b) - 1.0).abs() < 1e-6);
    }
}
