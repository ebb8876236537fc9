//! Image error metrics for comparing renders: HDR-FLIP and LDR-FLIP, RMSE and relative MSE.
//!
//! Images are [`RgbImage`]s: linear RGB, row-major, three `f32` per pixel, row 0 at the top.
//! Every metric compares a *test* image against a *reference* image of the same size:
//!
//! - [`hdr_flip`]: the mean of HDR-FLIP (Andersson et al., "Visualizing and Communicating Errors
//!   in Rendered Images", Ray Tracing Gems II, 2021), the perceptual difference of two HDR images
//!   over the range of exposures a viewer would plausibly use on them, in `[0, 1]`.
//!   [`hdr_flip_map`] gives the per-pixel error, for pictures.
//! - [`ldr_flip`]: the mean of LDR-FLIP (Andersson et al., "FLIP: A Difference Evaluator for
//!   Alternating Images", HPG 2020) for images already in `[0, 1]`; [`ldr_flip_map`] per pixel.
//! - [`rmse`]: `sqrt(mean((t - r)²))` over pixels and channels.
//! - [`rel_mse`]: `mean((t - r)² / (r² + ε))` over pixels and channels, with
//!   `ε = `[`REL_MSE_EPSILON`]` = 0.01`; the guard keeps black reference pixels from dominating.
//! - [`compare`]: all three of FLIP (HDR), relative MSE and RMSE at once.
//!
//! FLIP is a port of NVIDIA's reference implementation (`flip-evaluator` 1.7, `FLIP.h` in
//! NVlabs/flip) with its default parameters: [`PIXELS_PER_DEGREE`] (a 0.7 m wide 3840-pixel
//! monitor seen from 0.7 m) and the ACES tone mapper with automatic exposures. It works in `f32`
//! like the reference, pads image borders the same way (by repeating the edge pixel) and agrees
//! with it to about 1e-6 on the mean (the tests compare with `flip-evaluator` directly).
//!
//! Bad input is an error, never a panic or a meaningless number: sizes that differ
//! ([`MetricError::SizeMismatch`]), a buffer of the wrong length ([`MetricError::PixelCount`]), an
//! image without pixels ([`MetricError::Empty`]) and NaN or infinity in either image
//! ([`MetricError::NonFinite`], naming the image, pixel and channel).
//!
//! ```
//! use kiln_metrics::{RgbImage, compare, rmse};
//!
//! // A 2x1 image: a grey pixel and a bright one; the test is 0.1 brighter everywhere.
//! let reference = [0.5, 0.5, 0.5, 4.0, 4.0, 4.0];
//! let test = reference.map(|v| v + 0.1);
//! let r = RgbImage { width: 2, height: 1, pixels: &reference };
//! let t = RgbImage { width: 2, height: 1, pixels: &test };
//!
//! let errors = compare(r, t).unwrap();
//! assert!((errors.rmse - 0.1).abs() < 1e-6);
//! assert!(errors.flip > 0.0 && errors.flip < 1.0);
//!
//! // NaN is an error, not a number.
//! let broken = [0.5, f32::NAN, 0.5, 4.0, 4.0, 4.0];
//! let err = rmse(r, RgbImage { pixels: &broken, ..t }).unwrap_err();
//! assert_eq!(err.to_string(), "test image: NaN or infinity at pixel (0, 0), channel 1");
//! ```
//!
//! The FLIP functions run on rayon's thread pool.
#![deny(missing_docs)]

mod color;
mod fastmath;
mod flip;

/// Pixels per degree of visual angle that FLIP assumes: FLIP's default viewing conditions, a
/// 0.7 m wide monitor 3840 pixels across, seen from 0.7 m (`0.7 · 3840 / 0.7 · π / 180`,
/// evaluated in `f32` as the reference implementation does: 67.0206…).
pub const PIXELS_PER_DEGREE: f64 = 67.02064514160156;

/// The guard `ε` in [`rel_mse`]'s denominator `r² + ε`.
pub const REL_MSE_EPSILON: f64 = 1e-2;

/// A linear-radiance RGB image: row-major, row 0 at the top, 3 `f32` per pixel (R, G, B).
#[derive(Debug, Clone, Copy)]
pub struct RgbImage<'a> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width · height · 3` values.
    pub pixels: &'a [f32],
}

/// Why two images could not be compared.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MetricError {
    /// The images differ in size.
    #[error(
        "image sizes differ: reference is {}x{}, test is {}x{}",
        reference.0,
        reference.1,
        test.0,
        test.1
    )]
    SizeMismatch {
        /// The reference's width and height.
        reference: (u32, u32),
        /// The test image's width and height.
        test: (u32, u32),
    },
    /// An image's buffer does not hold `width · height · 3` values.
    #[error("{image} image: {width}x{height} needs {expected} values (3 per pixel), got {actual}")]
    PixelCount {
        /// `"reference"` or `"test"`.
        image: &'static str,
        /// The image's width.
        width: u32,
        /// The image's height.
        height: u32,
        /// `width · height · 3`.
        expected: u64,
        /// The buffer's length.
        actual: usize,
    },
    /// A value is NaN or infinite.
    #[error("{image} image: NaN or infinity at pixel ({x}, {y}), channel {channel}")]
    NonFinite {
        /// `"reference"` or `"test"`.
        image: &'static str,
        /// Column of the pixel.
        x: u32,
        /// Row of the pixel (0 at the top).
        y: u32,
        /// 0 for red, 1 for green, 2 for blue.
        channel: u32,
    },
    /// The images have no pixels (a width or height of 0).
    #[error("the images have no pixels ({width}x{height})")]
    Empty {
        /// The width.
        width: u32,
        /// The height.
        height: u32,
    },
}

/// The errors of a test image against a reference, as [`compare`] computes them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Errors {
    /// Mean HDR-FLIP, in `[0, 1]` ([`hdr_flip`]).
    pub flip: f64,
    /// Relative mean squared error ([`rel_mse`]).
    pub rel_mse: f64,
    /// Root mean squared error ([`rmse`]).
    pub rmse: f64,
}

/// Checks one image's buffer length; returns the number of values.
fn check_len(image: &'static str, img: &RgbImage) -> Result<usize, MetricError> {
    let expected = u64::from(img.width) * u64::from(img.height) * 3;
    if expected != img.pixels.len() as u64 {
        return Err(MetricError::PixelCount {
            image,
            width: img.width,
            height: img.height,
            expected,
            actual: img.pixels.len(),
        });
    }
    Ok(img.pixels.len())
}

/// The first NaN or infinity in an image, as an error.
fn check_finite(image: &'static str, img: &RgbImage) -> Result<(), MetricError> {
    match img.pixels.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => {
            let pixel = i / 3;
            let width = img.width as usize;
            Err(MetricError::NonFinite {
                image,
                x: (pixel % width) as u32,
                y: (pixel / width) as u32,
                channel: (i % 3) as u32,
            })
        }
    }
}

/// Validates a pair of images: same size, right buffer lengths, some pixels, finite values.
fn validate(reference: &RgbImage, test: &RgbImage) -> Result<(), MetricError> {
    check_len("reference", reference)?;
    check_len("test", test)?;
    if (reference.width, reference.height) != (test.width, test.height) {
        return Err(MetricError::SizeMismatch {
            reference: (reference.width, reference.height),
            test: (test.width, test.height),
        });
    }
    if reference.pixels.is_empty() {
        return Err(MetricError::Empty { width: reference.width, height: reference.height });
    }
    check_finite("reference", reference)?;
    check_finite("test", test)
}

/// Root mean squared error: `sqrt(mean((t - r)²))` over all pixels and channels, in `f64`.
pub fn rmse(reference: RgbImage, test: RgbImage) -> Result<f64, MetricError> {
    validate(&reference, &test)?;
    Ok(mse(reference.pixels, test.pixels).sqrt())
}

fn mse(reference: &[f32], test: &[f32]) -> f64 {
    let sum: f64 = reference
        .iter()
        .zip(test)
        .map(|(&r, &t)| {
            let d = f64::from(t) - f64::from(r);
            d * d
        })
        .sum();
    sum / reference.len() as f64
}

/// Relative mean squared error: `mean((t - r)² / (r² + ε))` over all pixels and channels, with
/// `ε = `[`REL_MSE_EPSILON`]` = 0.01`, in `f64`.
///
/// Dividing by the reference's square weighs errors relative to the brightness they occur at, as
/// the eye does; `ε` keeps (nearly) black reference values from dividing by (nearly) zero.
pub fn rel_mse(reference: RgbImage, test: RgbImage) -> Result<f64, MetricError> {
    validate(&reference, &test)?;
    Ok(rel_mse_unchecked(reference.pixels, test.pixels))
}

fn rel_mse_unchecked(reference: &[f32], test: &[f32]) -> f64 {
    let sum: f64 = reference
        .iter()
        .zip(test)
        .map(|(&r, &t)| {
            let (r, t) = (f64::from(r), f64::from(t));
            (t - r) * (t - r) / (r * r + REL_MSE_EPSILON)
        })
        .sum();
    sum / reference.len() as f64
}

/// Mean HDR-FLIP of `test` against `reference` (linear RGB, any non-negative radiance), in
/// `[0, 1]`, with FLIP's default parameters: [`PIXELS_PER_DEGREE`], the ACES tone mapper and the
/// exposure range computed from the reference.
///
/// HDR-FLIP tone-maps both images at a series of exposures, evaluates LDR-FLIP at each and keeps
/// each pixel's largest error. The exposures run from the one that maps the reference's brightest
/// luminance to 85% of the tone mapper's output to the one that does so for its median
/// luminance, one stop apart or closer (at least 2 exposures). Where more than half the
/// reference is black (a median luminance of 0, for which the reference implementation has no
/// answer), the darkest non-black luminance stands in for the median; a black reference gets the
/// exposure range [0, 0].
pub fn hdr_flip(reference: RgbImage, test: RgbImage) -> Result<f64, MetricError> {
    Ok(mean(&hdr_flip_map(reference, test)?))
}

/// Per-pixel HDR-FLIP (row-major, one value in `[0, 1]` per pixel) of `test` against
/// `reference`; [`hdr_flip`] is its mean.
pub fn hdr_flip_map(reference: RgbImage, test: RgbImage) -> Result<Vec<f32>, MetricError> {
    validate(&reference, &test)?;
    Ok(flip::hdr_flip_map(&flip::Frame::new(&reference), test.pixels))
}

/// Mean LDR-FLIP of `test` against `reference`, in `[0, 1]`, with [`PIXELS_PER_DEGREE`].
///
/// The images are linear RGB with values in `[0, 1]` (values outside are clamped to it, as the
/// reference implementation does); this is `flip_evaluator.evaluate(reference, test, "LDR",
/// inputsRGB=False)`. sRGB-encoded images (8-bit PNGs and the like) must be decoded to linear
/// first.
pub fn ldr_flip(reference: RgbImage, test: RgbImage) -> Result<f64, MetricError> {
    Ok(mean(&ldr_flip_map(reference, test)?))
}

/// Per-pixel LDR-FLIP (row-major, one value in `[0, 1]` per pixel) of `test` against
/// `reference`; [`ldr_flip`] is its mean.
pub fn ldr_flip_map(reference: RgbImage, test: RgbImage) -> Result<Vec<f32>, MetricError> {
    validate(&reference, &test)?;
    Ok(flip::ldr_flip_map(&flip::Frame::new(&reference), test.pixels))
}

/// Mean HDR-FLIP, relative MSE and RMSE of `test` against `reference`.
pub fn compare(reference: RgbImage, test: RgbImage) -> Result<Errors, MetricError> {
    Ok(compare_with_map(reference, test)?.0)
}

/// [`compare`], with the per-pixel HDR-FLIP whose mean it reports (as [`hdr_flip_map`]).
pub fn compare_with_map(reference: RgbImage, test: RgbImage) -> Result<(Errors, Vec<f32>), MetricError> {
    validate(&reference, &test)?;
    let map = flip::hdr_flip_map(&flip::Frame::new(&reference), test.pixels);
    let errors = Errors {
        flip: mean(&map),
        rel_mse: rel_mse_unchecked(reference.pixels, test.pixels),
        rmse: mse(reference.pixels, test.pixels).sqrt(),
    };
    Ok((errors, map))
}

fn mean(map: &[f32]) -> f64 {
    map.iter().map(|&v| f64::from(v)).sum::<f64>() / map.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_per_degree_is_flips_default_in_f32() {
        let ppd = 0.7f32 * (3840.0f32 / 0.7) * (std::f32::consts::PI / 180.0);
        assert_eq!(PIXELS_PER_DEGREE as f32, ppd);
        assert_eq!(PIXELS_PER_DEGREE, f64::from(ppd));
    }
}
