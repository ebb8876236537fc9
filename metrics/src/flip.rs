//! LDR-FLIP and HDR-FLIP.
//!
//! LDR-FLIP (Andersson et al. 2020) compares two images the way an observer flipping between them
//! would see the difference:
//!
//! 1. Both images go to YCxCz and are blurred with the contrast sensitivity functions of the
//!    achromatic and the two chromatic channels (sums of Gaussians, sized in pixels from the
//!    pixels per degree of visual angle), which removes what the eye cannot resolve.
//! 2. The blurred pixels are clamped to the RGB gamut, moved to CIELAB with the Hunt adjustment,
//!    and their HyAB distance is remapped onto `[0, 1]`: the colour error.
//! 3. Edges and points (first and second Gaussian derivatives of the luminance) are detected in
//!    both images; the difference of their strengths is the feature error `f`.
//! 4. The error is `colour^(1 - f)`: a changed edge or point amplifies the colour error.
//!
//! HDR-FLIP (Andersson et al. 2021) tone-maps both images at a range of exposures, runs LDR-FLIP
//! on each pair and keeps each pixel's maximum.
//!
//! Numerics follow NVIDIA's reference (`FLIP.h`, version 1.6/1.7): `f32` throughout, the same
//! filter radii and normalisations, borders padded by repeating the edge pixel, and the same
//! order of summation in the filters. Both filters are applied separably (see
//! `misc/separatedConvolutions.pdf` in NVlabs/flip): the CSF of the blue-yellow channel, a sum of
//! two Gaussians, is split into two separable Gaussians whose results are added.
//!
//! Layout: a horizontal pass turns each input row into [`PLANES`] filtered rows (the row-major
//! "plane per row" buffer `rows`), and a vertical pass filters those and computes each pixel's
//! error. Both passes work on whole rows so that the inner loops run over contiguous `f32`s
//! and vectorise; rayon spreads the rows over the cores.

use rayon::prelude::*;

use crate::color::{self, ColorScale};
use crate::fastmath;

/// A validated image: `width · height · 3` finite values, at least one pixel.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame<'a> {
    width: usize,
    height: usize,
    pixels: &'a [f32],
}

impl<'a> Frame<'a> {
    pub(crate) fn new(image: &crate::RgbImage<'a>) -> Self {
        Frame { width: image.width as usize, height: image.height as usize, pixels: image.pixels }
    }
}

/// The reference implementation's π in `f32`.
const PI: f32 = std::f32::consts::PI;

/// Weber-like width of the edge and point detectors, in degrees (`w` in the FLIP paper).
const FEATURE_WIDTH: f32 = 0.082;
/// Exponent on the feature difference (`q_f`).
const QF: f32 = 0.5;

/// The contrast sensitivity functions as sums of Gaussians `a · sqrt(π/b) · exp(−π² x² / b)`
/// (FLIP paper, table 1): (a1, b1, a2, b2) for the Y, Cx and Cz channels. Only Cz has a second
/// Gaussian.
const CSF_Y: (f32, f32) = (1.0, 0.0047);
const CSF_CX: (f32, f32) = (1.0, 0.0053);
const CSF_CZ: [(f32, f32); 2] = [(34.1, 0.04), (13.5, 0.025)];
/// The largest `b` of all the Gaussians above (including the reference's unused `b2 = 1e-5` of
/// Y and Cx): it sets the CSF filters' radius.
const CSF_MAX_B: f32 = 0.04;

/// The 1D filters, normalised as the reference normalises them.
#[derive(Debug)]
struct Kernels {
    /// CSF filters, all `2 · csf_radius + 1` taps: Y, Cx and the two parts of Cz.
    csf: [Vec<f32>; 4],
    csf_radius: usize,
    /// Feature filters, `2 · feature_radius + 1` taps: Gaussian, its first and second derivative.
    gauss: Vec<f32>,
    d1: Vec<f32>,
    d2: Vec<f32>,
    feature_radius: usize,
}

impl Kernels {
    fn new(ppd: f32) -> Self {
        Kernels::with_csf(ppd).with_features(ppd)
    }

    /// CSF filters: the continuous CSF sampled at pixel spacing `1/ppd` degrees, out to three
    /// standard deviations of the widest Gaussian.
    fn with_csf(ppd: f32) -> Self {
        let pi_sq = PI * PI;
        let radius = (3.0 * (CSF_MAX_B / (2.0 * pi_sq)).sqrt() * ppd).ceil() as usize;
        let sample = |i: usize| {
            let x = (i as f32 - radius as f32) * (1.0 / ppd);
            x * x
        };
        let gaussian = |x2: f32, (a, b): (f32, f32)| a * (PI / b).sqrt() * (-pi_sq * x2 / b).exp();
        // The Cz filter is a sum of two 2D Gaussians; separated, each 1D half carries the square
        // root of its amplitude so that the product of the two passes has the full amplitude.
        let gaussian_sqrt =
            |x2: f32, (a, b): (f32, f32)| (a * (PI / b).sqrt()).sqrt() * (-pi_sq * x2 / b).exp();
        let taps = 2 * radius + 1;
        let y: Vec<f32> = (0..taps).map(|i| gaussian(sample(i), CSF_Y)).collect();
        let cx: Vec<f32> = (0..taps).map(|i| gaussian(sample(i), CSF_CX)).collect();
        let cz1: Vec<f32> = (0..taps).map(|i| gaussian_sqrt(sample(i), CSF_CZ[0])).collect();
        let cz2: Vec<f32> = (0..taps).map(|i| gaussian_sqrt(sample(i), CSF_CZ[1])).collect();
        // Y and Cx each sum to 1 (in 1D, hence in 2D). The two Cz parts share one factor s
        // chosen so that the 2D Cz filter, whose weights sum to s² ((Σ cz1)² + (Σ cz2)²), sums
        // to 1.
        let sum = |v: &[f32]| v.iter().fold(0.0f32, |s, &w| s + w);
        let (sy, scx) = (1.0 / sum(&y), 1.0 / sum(&cx));
        let scz = 1.0 / (sum(&cz1) * sum(&cz1) + sum(&cz2) * sum(&cz2)).sqrt();
        let scale = |v: Vec<f32>, s: f32| v.into_iter().map(|w| w * s).collect::<Vec<_>>();
        Kernels {
            csf: [scale(y, sy), scale(cx, scx), scale(cz1, scz), scale(cz2, scz)],
            csf_radius: radius,
            gauss: Vec::new(),
            d1: Vec::new(),
            d2: Vec::new(),
            feature_radius: 0,
        }
    }

    /// Edge and point detectors: a Gaussian of standard deviation `w/2` degrees and its first and
    /// second derivatives, out to three standard deviations. The Gaussian sums to 1; the
    /// derivatives' positive weights sum to 1 and their negative weights to −1, so that their
    /// responses are comparable between images and bounded.
    fn with_features(mut self, ppd: f32) -> Self {
        let sigma = 0.5 * FEATURE_WIDTH * ppd;
        let radius = (3.0 * sigma).ceil() as usize;
        let xs = (0..2 * radius + 1).map(|i| i as f32 - radius as f32);
        let g: Vec<f32> = xs.clone().map(|x| (-(x * x) / (2.0 * sigma * sigma)).exp()).collect();
        let d1: Vec<f32> = xs.clone().zip(&g).map(|(x, &g)| -x * g).collect();
        let d2: Vec<f32> = xs.zip(&g).map(|(x, &g)| (x * x / (sigma * sigma) - 1.0) * g).collect();
        let gsum = g.iter().fold(0.0f32, |s, &w| s + w);
        // Sums of the positive and of the (negated) negative weights, in tap order.
        let split = |v: &[f32]| {
            v.iter().fold((0.0f32, 0.0f32), |(p, n), &w| if w > 0.0 { (p + w, n) } else { (p, n - w) })
        };
        let balance = |v: Vec<f32>| {
            let (pos, neg) = split(&v);
            v.into_iter().map(|w| w / if w > 0.0 { pos } else { neg }).collect()
        };
        self.gauss = g.into_iter().map(|w| w / gsum).collect();
        self.d1 = balance(d1);
        self.d2 = balance(d2);
        self.feature_radius = radius;
        self
    }

    /// Padding each row needs on either side.
    fn pad(&self) -> usize {
        self.csf_radius.max(self.feature_radius)
    }
}

/// Filtered rows per input row: for the reference, then the test image, the horizontal passes
/// of Y, Cx, Cz (twice, one per Cz Gaussian) with the CSF filters and of the normalised
/// luminance with the feature filters' first derivative, second derivative and Gaussian.
const PLANES: usize = 14;
const PER_IMAGE: usize = 7;

/// Horizontally filters one row of `pixels` (interleaved linear RGB), mapped by `tone` (the
/// exposure and tone mapper, then the clamp to `[0, 1]`), into its 7 planes of `out`.
fn horizontal_row(
    pixels: &[f32],
    tone: &(impl Fn(f32) -> f32 + Sync),
    k: &Kernels,
    padded: &mut [Vec<f32>; 4],
    out: &mut [f32],
) {
    let w = pixels.len() / 3;
    let pad = k.pad();
    // Y, Cx, Cz and the luminance normalised to [0, 1], padded by repeating the edge pixels (the
    // reference clamps its sample coordinates to the image).
    for (x, rgb) in pixels.chunks_exact(3).enumerate() {
        let [y, cx, cz] = color::linear_rgb_to_ycxcz([tone(rgb[0]), tone(rgb[1]), tone(rgb[2])]);
        padded[0][pad + x] = y;
        padded[1][pad + x] = cx;
        padded[2][pad + x] = cz;
        padded[3][pad + x] = y * (1.0 / 116.0) + 16.0 / 116.0;
    }
    for row in padded.iter_mut() {
        let (first, last) = (row[pad], row[pad + w - 1]);
        row[..pad].fill(first);
        row[pad + w..].fill(last);
    }
    let mut planes = out.chunks_exact_mut(w);
    let mut next = || planes.next().expect("7 planes per image");
    convolve_row(&padded[0], pad, &k.csf[0], next());
    convolve_row(&padded[1], pad, &k.csf[1], next());
    convolve_row(&padded[2], pad, &k.csf[2], next());
    convolve_row(&padded[2], pad, &k.csf[3], next());
    convolve_row(&padded[3], pad, &k.d1, next());
    convolve_row(&padded[3], pad, &k.d2, next());
    convolve_row(&padded[3], pad, &k.gauss, next());
}

/// `out[x] = Σ_i kernel[i] · padded[pad + x + i − r]`, summed in tap order like the reference.
fn convolve_row(padded: &[f32], pad: usize, kernel: &[f32], out: &mut [f32]) {
    let start = pad - kernel.len() / 2;
    let n = out.len();
    // The first tap assigns (0 + w·s is w·s), the others add.
    for (o, &s) in out.iter_mut().zip(&padded[start..start + n]) {
        *o = kernel[0] * s;
    }
    for (i, &weight) in kernel.iter().enumerate().skip(1) {
        for (o, &s) in out.iter_mut().zip(&padded[start + i..start + i + n]) {
            *o += weight * s;
        }
    }
}

/// `acc[x] = Σ_i kernel[i] · plane(y + i − r)[x]`, rows clamped to the image.
fn convolve_column(
    rows: &[f32],
    w: usize,
    h: usize,
    y: usize,
    plane: usize,
    kernel: &[f32],
    acc: &mut [f32],
) {
    let r = kernel.len() / 2;
    let row = |i: usize| {
        let yy = (y + i).saturating_sub(r).min(h - 1);
        let start = (yy * PLANES + plane) * w;
        &rows[start..start + w]
    };
    // The first tap assigns (0 + w·s is w·s), the others add.
    for (a, &s) in acc.iter_mut().zip(row(0)) {
        *a = kernel[0] * s;
    }
    for (i, &weight) in kernel.iter().enumerate().skip(1) {
        for (a, &s) in acc.iter_mut().zip(row(i)) {
            *a += weight * s;
        }
    }
}

/// Vertically filtered values for one output row: per image, Y, Cx, Cz (two parts), and the
/// luminance's x derivative, x second derivative, y derivative and y second derivative.
const ACCUMULATORS: usize = 16;

/// Finishes one output row: vertical filtering, colour error, feature error, FLIP error.
fn vertical_row(rows: &[f32], w: usize, h: usize, y: usize, k: &Kernels, acc: &mut [f32], out: &mut [f32]) {
    let mut accs = acc.chunks_exact_mut(w);
    for image in 0..2 {
        let base = image * PER_IMAGE;
        for (p, kernel) in k.csf.iter().enumerate() {
            convolve_column(rows, w, h, y, base + p, kernel, accs.next().expect("16"));
        }
        // Separable 2D derivatives: d/dx is (x derivative) ⊗ (y Gaussian), d/dy the converse.
        convolve_column(rows, w, h, y, base + 4, &k.gauss, accs.next().expect("16"));
        convolve_column(rows, w, h, y, base + 5, &k.gauss, accs.next().expect("16"));
        convolve_column(rows, w, h, y, base + 6, &k.d1, accs.next().expect("16"));
        convolve_column(rows, w, h, y, base + 6, &k.d2, accs.next().expect("16"));
    }
    // The per-pixel stage, as passes over whole rows of plain arrays so that each loop
    // compiles to vector code (the colour conversions and powers are inline and branch-free).
    let (acc, extra) = acc.split_at_mut(ACCUMULATORS * w);
    let [l_r, a_r, b_r, l_t, a_t, b_t] = split6(extra, w);
    let plane = |i: usize| &acc[i * w..(i + 1) * w];
    hunt_lab_row([plane(0), plane(1), plane(2), plane(3)], [l_r, a_r, b_r]);
    hunt_lab_row([plane(8), plane(9), plane(10), plane(11)], [l_t, a_t, b_t]);
    let scale = ColorScale::new();
    let features_r = [plane(4), plane(5), plane(6), plane(7)];
    let features_t = [plane(12), plane(13), plane(14), plane(15)];
    let (l_r, a_r, b_r, l_t, a_t, b_t) = (&l_r[..w], &a_r[..w], &b_r[..w], &l_t[..w], &a_t[..w], &b_t[..w]);
    let out = &mut out[..w];
    for x in 0..w {
        let color_error = scale.error([l_r[x], a_r[x], b_r[x]], [l_t[x], a_t[x], b_t[x]]);
        let feature_error = feature_error(features_r.map(|p| p[x]), features_t.map(|p| p[x]));
        out[x] = fastmath::pow(color_error, 1.0 - feature_error);
    }
}

/// Six row-length slices of `buf`.
fn split6(buf: &mut [f32], w: usize) -> [&mut [f32]; 6] {
    let mut rows = buf.chunks_exact_mut(w);
    std::array::from_fn(|_| rows.next().expect("6 rows of scratch"))
}

/// Hunt-adjusted CIELAB of a row of filtered pixels given as Y, Cx and the two parts of Cz.
fn hunt_lab_row(ycxcz: [&[f32]; 4], lab: [&mut [f32]; 3]) {
    let n = lab[0].len();
    let [y, cx, cz1, cz2] = ycxcz.map(|p| &p[..n]);
    let [l, a, b] = lab.map(|p| &mut p[..n]);
    for x in 0..n {
        [l[x], a[x], b[x]] = color::filtered_to_hunt_lab([y[x], cx[x], cz1[x] + cz2[x]]);
    }
}

/// The feature error in [0, 1] from the filtered luminance derivatives (x, xx, y, yy) of the
/// reference and the test pixel: the larger difference of edge strength (gradient magnitude) and
/// of point strength (magnitude of the second derivatives), scaled to [0, 1] by 1/√2, to the
/// power q_f = ½.
#[inline(always)]
fn feature_error(reference: [f32; 4], test: [f32; 4]) -> f32 {
    let strengths =
        |[dx, ddx, dy, ddy]: [f32; 4]| ((dx * dx + dy * dy).sqrt(), (ddx * ddx + ddy * ddy).sqrt());
    let (edge_r, point_r) = strengths(reference);
    let (edge_t, point_t) = strengths(test);
    let difference = (edge_r - edge_t).abs().max((point_r - point_t).abs());
    const { assert!(QF == 0.5) };
    (std::f32::consts::FRAC_1_SQRT_2 * difference).sqrt()
}

/// Scratch buffers reused between exposures.
struct Work {
    kernels: Kernels,
    rows: Vec<f32>,
}

impl Work {
    fn new(frame: &Frame) -> Self {
        let ppd = crate::PIXELS_PER_DEGREE as f32;
        Work { kernels: Kernels::new(ppd), rows: vec![0.0; frame.width * frame.height * PLANES] }
    }

    /// LDR-FLIP of the two images after `tone`, into `out` (one value per pixel).
    fn ldr_flip(&mut self, frame: &Frame, test: &[f32], tone: impl Fn(f32) -> f32 + Sync, out: &mut [f32]) {
        let (w, h) = (frame.width, frame.height);
        let k = &self.kernels;
        let padded_len = w + 2 * k.pad();
        self.rows.par_chunks_mut(PLANES * w).enumerate().for_each_init(
            || std::array::from_fn(|_| vec![0.0f32; padded_len]),
            |padded, (y, out)| {
                let (out_ref, out_test) = out.split_at_mut(PER_IMAGE * w);
                let row = 3 * w * y..3 * w * (y + 1);
                horizontal_row(&frame.pixels[row.clone()], &tone, k, padded, out_ref);
                horizontal_row(&test[row], &tone, k, padded, out_test);
            },
        );
        let rows = &self.rows;
        out.par_chunks_mut(w).enumerate().for_each_init(
            || vec![0.0f32; (ACCUMULATORS + 6) * w],
            |acc, (y, out)| vertical_row(rows, w, h, y, k, acc, out),
        );
    }
}

/// LDR-FLIP map; values outside `[0, 1]` are clamped first.
pub(crate) fn ldr_flip_map(reference: &Frame, test: &[f32]) -> Vec<f32> {
    let mut map = vec![0.0; reference.width * reference.height];
    Work::new(reference).ldr_flip(reference, test, color::clamp01, &mut map);
    map
}

/// ACES filmic tone mapper (Narkowicz's fit) as the rational `(c0 x² + c1 x + c2) / (c3 x² + c4 x +
/// c5)`, with the reference's 0.6 pre-exposure folded into the coefficients.
const ACES: [f32; 6] = [0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14];

fn aces(x: f32) -> f32 {
    let c = &ACES;
    (x * x * c[0] + x * c[1] + c[2]) / (x * x * c[3] + x * c[4] + c[5])
}

/// The exposure range of HDR-FLIP (Andersson et al. 2021, section 3): (start, stop, count), in
/// stops (log2 of the multiplier).
///
/// The start exposure maps the reference's largest luminance to where the tone mapper outputs
/// 0.85, so the brightest parts are seen without clipping; the stop exposure does the same for
/// the median luminance, so that the darker half is seen well too. In between, at most one stop
/// apart, at least 2 exposures.
fn exposures(frame: &Frame) -> (f32, f32, usize) {
    // The input x at which the tone mapper outputs t: solve (c0 − t c3) x² + (c1 − t c4) x +
    // (c2 − t c5) = 0 and take the larger root.
    let t = 0.85f32;
    let c = &ACES;
    let (a, b, cc) = (c[0] - t * c[3], c[1] - t * c[4], c[2] - t * c[5]);
    let half = -0.5 * (b / a);
    let x_max = half + (half * half - cc / a).sqrt();

    // Luminances, capped at f32::MAX so that an overflow cannot make the range infinite.
    let mut lum: Vec<f32> =
        frame.pixels.chunks_exact(3).map(|p| color::luminance([p[0], p[1], p[2]]).min(f32::MAX)).collect();
    let y_max = lum.iter().fold(-1e30f32, |m, &l| if m < l { l } else { m });
    let y_min_positive = lum.iter().fold(f32::INFINITY, |m, &l| if l > 0.0 && l < m { l } else { m });
    let mid = lum.len() / 2;
    let y_median = *lum.select_nth_unstable_by(mid, f32::total_cmp).1;

    if !(y_max > 0.0) {
        // A black (or negative) reference: nothing to expose for.
        return (0.0, 0.0, 2);
    }
    // More than half the reference black: the reference implementation would divide by zero;
    // the darkest lit pixel is the best stand-in for "the darker half".
    let y_low = if y_median > 0.0 { y_median } else { y_min_positive };
    let stops = |y: f32| {
        let ratio = x_max / y;
        let ratio = if ratio.is_finite() { f64::from(ratio) } else { f64::from(x_max) / f64::from(y) };
        ratio.log2() as f32
    };
    let (start, stop) = (stops(y_max), stops(y_low));
    let count = (stop - start).ceil().max(2.0) as usize;
    (start, stop, count)
}

/// HDR-FLIP map: the per-pixel maximum of LDR-FLIP over the exposures.
pub(crate) fn hdr_flip_map(reference: &Frame, test: &[f32]) -> Vec<f32> {
    let (start, stop, count) = exposures(reference);
    let step = (stop - start) / (count - 1) as f32;
    let mut work = Work::new(reference);
    let mut map = vec![0.0f32; reference.width * reference.height];
    let mut exposure_map = vec![0.0f32; map.len()];
    for i in 0..count {
        let exposure = start + i as f32 * step;
        let m = 2.0f32.powf(exposure);
        work.ldr_flip(reference, test, |v| color::clamp01(aces(v * m)), &mut exposure_map);
        map.par_iter_mut().zip(&exposure_map).for_each(|(max, &e)| {
            if e > *max {
                *max = e;
            }
        });
    }
    map
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_at_default_ppd() {
        let k = Kernels::new(crate::PIXELS_PER_DEGREE as f32);
        assert_eq!(k.csf_radius, 10);
        assert_eq!(k.feature_radius, 9);
        for kernel in &k.csf[..2] {
            assert!((kernel.iter().sum::<f32>() - 1.0).abs() < 1e-5);
        }
        assert!((k.gauss.iter().sum::<f32>() - 1.0).abs() < 1e-5);
        for d in [&k.d1, &k.d2] {
            assert!((d.iter().filter(|&&w| w > 0.0).sum::<f32>() - 1.0).abs() < 1e-5);
            assert!((d.iter().filter(|&&w| w < 0.0).sum::<f32>() + 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn aces_hits_085_at_x_max() {
        let frame = Frame { width: 1, height: 1, pixels: &[1.0, 1.0, 1.0] };
        let (start, _, _) = exposures(&frame);
        assert!((aces(2.0f32.powf(start)) - 0.85).abs() < 1e-5);
    }

    #[test]
    fn black_reference_has_a_finite_range() {
        let frame = Frame { width: 2, height: 1, pixels: &[0.0; 6] };
        assert_eq!(exposures(&frame), (0.0, 0.0, 2));
        // Mostly black: the darkest lit pixel stands in for the median.
        let frame = Frame { width: 3, height: 1, pixels: &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0] };
        let (start, stop, count) = exposures(&frame);
        assert_eq!((start, stop, count), (start, start, 2));
    }
}
