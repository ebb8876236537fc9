//! RMSE and relative MSE against hand-computed values, and every metric's handling of bad input:
//! errors naming what is wrong, never a panic or a number.

use kiln_metrics::{
    Errors, MetricError, REL_MSE_EPSILON, RgbImage, compare, hdr_flip, hdr_flip_map, ldr_flip, ldr_flip_map,
    rel_mse, rmse,
};

fn img(width: u32, height: u32, pixels: &[f32]) -> RgbImage<'_> {
    RgbImage { width, height, pixels }
}

/// A 2x2 grey image of 0, 0.5, 1 and 2, and the same plus 0.25 (all exact in f32).
fn offset_pair() -> (Vec<f32>, Vec<f32>) {
    let reference: Vec<f32> = [0.0f32, 0.5, 1.0, 2.0].iter().flat_map(|&v| [v; 3]).collect();
    let test = reference.iter().map(|v| v + 0.25).collect();
    (reference, test)
}

#[test]
fn rmse_of_a_constant_offset_is_the_offset() {
    let (r, t) = offset_pair();
    assert_eq!(rmse(img(2, 2, &r), img(2, 2, &t)).unwrap(), 0.25);
}

#[test]
fn rel_mse_of_a_constant_offset() {
    let (r, t) = offset_pair();
    assert_eq!(REL_MSE_EPSILON, 0.01);
    // mean of 0.25² / (r² + 0.01) over r = 0, 0.5, 1, 2 (each for three channels).
    let want = (0.0625 / 0.01 + 0.0625 / 0.26 + 0.0625 / 1.01 + 0.0625 / 4.01) / 4.0;
    let got = rel_mse(img(2, 2, &r), img(2, 2, &t)).unwrap();
    assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    assert!((want - 1.641962959).abs() < 1e-9);
}

#[test]
fn compare_returns_all_three() {
    let (r, t) = offset_pair();
    let (r, t) = (img(2, 2, &r), img(2, 2, &t));
    let e = compare(r, t).unwrap();
    assert_eq!(
        e,
        Errors { flip: hdr_flip(r, t).unwrap(), rel_mse: rel_mse(r, t).unwrap(), rmse: rmse(r, t).unwrap() }
    );
    assert!(e.flip > 0.0 && e.flip <= 1.0);
}

#[test]
fn identical_images_have_no_error() {
    let pixels: Vec<f32> = (0..24 * 17 * 3).map(|i| ((i * 7919) % 1000) as f32 / 100.0).collect();
    let a = img(24, 17, &pixels);
    assert_eq!(compare(a, a).unwrap(), Errors { flip: 0.0, rel_mse: 0.0, rmse: 0.0 });
    assert!(hdr_flip_map(a, a).unwrap().iter().all(|&v| v == 0.0));
    let ldr: Vec<f32> = pixels.iter().map(|v| v / 10.0).collect();
    assert_eq!(ldr_flip(img(24, 17, &ldr), img(24, 17, &ldr)).unwrap(), 0.0);
}

/// Calls every metric on the pair; all must give the same error.
fn all_fail(r: RgbImage, t: RgbImage) -> MetricError {
    let e = rmse(r, t).unwrap_err();
    assert_eq!(rel_mse(r, t).unwrap_err(), e);
    assert_eq!(compare(r, t).unwrap_err(), e);
    assert_eq!(hdr_flip(r, t).unwrap_err(), e);
    assert_eq!(hdr_flip_map(r, t).unwrap_err(), e);
    assert_eq!(ldr_flip(r, t).unwrap_err(), e);
    assert_eq!(ldr_flip_map(r, t).unwrap_err(), e);
    e
}

#[test]
fn non_finite_values_are_errors_naming_image_pixel_and_channel() {
    let good = vec![0.5f32; 3 * 2 * 3];
    for bad_value in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut bad = good.clone();
        // Pixel (1, 2) of a 2x3 image, blue.
        bad[(2 * 2 + 1) * 3 + 2] = bad_value;
        let e = all_fail(img(2, 3, &bad), img(2, 3, &good));
        assert_eq!(e, MetricError::NonFinite { image: "reference", x: 1, y: 2, channel: 2 });
        assert_eq!(e.to_string(), "reference image: NaN or infinity at pixel (1, 2), channel 2");

        let mut bad = good.clone();
        bad[3] = bad_value; // Pixel (1, 0), red.
        let e = all_fail(img(2, 3, &good), img(2, 3, &bad));
        assert_eq!(e, MetricError::NonFinite { image: "test", x: 1, y: 0, channel: 0 });
    }
}

#[test]
fn size_mismatch_names_both_sizes() {
    let a = vec![0.5f32; 4 * 3 * 3];
    let b = vec![0.5f32; 3 * 4 * 3];
    let e = all_fail(img(4, 3, &a), img(3, 4, &b));
    assert_eq!(e, MetricError::SizeMismatch { reference: (4, 3), test: (3, 4) });
    assert_eq!(e.to_string(), "image sizes differ: reference is 4x3, test is 3x4");
}

#[test]
fn wrong_pixel_count_is_an_error() {
    let a = vec![0.5f32; 4 * 3 * 3];
    let short = &a[..a.len() - 1];
    let e = all_fail(img(4, 3, &a), img(4, 3, short));
    assert_eq!(e, MetricError::PixelCount { image: "test", width: 4, height: 3, expected: 36, actual: 35 });
    assert_eq!(e.to_string(), "test image: 4x3 needs 36 values (3 per pixel), got 35");
    // A size whose pixel count overflows 32 bits must not wrap around.
    let e = all_fail(img(u32::MAX, u32::MAX, &a), img(4, 3, &a));
    assert!(matches!(e, MetricError::PixelCount { image: "reference", actual: 36, .. }), "{e:?}");
}

#[test]
fn empty_images_are_errors() {
    for (w, h) in [(0, 0), (0, 5), (5, 0)] {
        let e = all_fail(img(w, h, &[]), img(w, h, &[]));
        assert_eq!(e, MetricError::Empty { width: w, height: h });
    }
}

#[test]
fn tiny_and_thin_images_work() {
    for (w, h) in [(1, 1), (1, 9), (9, 1), (2, 2)] {
        let n = (w * h * 3) as usize;
        let r: Vec<f32> = (0..n).map(|i| 0.1 + i as f32).collect();
        let t: Vec<f32> = r.iter().map(|v| v * 1.5).collect();
        for f in [hdr_flip(img(w, h, &r), img(w, h, &t)), ldr_flip(img(w, h, &r), img(w, h, &t))] {
            let f = f.unwrap();
            assert!(f > 0.0 && f <= 1.0, "{w}x{h}: {f}");
        }
    }
}

#[test]
fn extreme_values_give_a_number_in_range() {
    // Huge, tiny, negative and mostly-black references: the exposure range stays finite.
    let cases: [(&[f32], &[f32]); 4] = [
        (&[3e38, 3e38, 3e38, 1.0, 1.0, 1.0], &[1.0, 1.0, 1.0, 3e38, 0.0, 3e38]),
        (&[1e-44, 0.0, 0.0, 1e-40, 1e-40, 1e-40], &[0.0, 1e-40, 0.0, 1.0, 1.0, 1.0]),
        (&[-1.0, -2.0, -3.0, -1.0, 0.0, 0.0], &[1.0, 2.0, 3.0, 0.0, 0.0, 0.0]),
        (&[0.0, 0.0, 0.0, 5.0, 5.0, 5.0], &[0.0, 0.0, 0.0, 2.0, 5.0, 5.0]),
    ];
    for (r, t) in cases {
        let map = hdr_flip_map(img(2, 1, r), img(2, 1, t)).unwrap();
        assert!(map.iter().all(|v| (0.0..=1.0).contains(v)), "{r:?} {t:?}: {map:?}");
    }
}
