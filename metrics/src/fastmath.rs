//! Branch-free `f32` cube root and power for FLIP's per-pixel stage.
//!
//! libm's `cbrtf` and `powf` are calls the compiler cannot vectorise, and they took about 30% of
//! HDR-FLIP's time. These inline versions compile to straight-line code that vectorises over a
//! row, and are accurate to a few ulp over the ranges FLIP uses (checked against libm in the
//! tests below), far below what moves a mean error.

/// Cube root of `v ≥ 0` (`v` not subnormal, or the result is approximate).
#[inline(always)]
pub(crate) fn cbrt(v: f32) -> f32 {
    // Initial guess: divide the exponent by 3 by treating the bits as a number (a third of the
    // bits plus a third of the bias of 1.0's bits), about 3% off. Done in f32 so it vectorises.
    let bits = v.to_bits() as i32 as f32;
    let mut y = f32::from_bits((bits * (1.0 / 3.0) + (2.0 / 3.0) * 1_065_353_216.0) as i32 as u32);
    // Newton on y³ = v; each step squares the relative error (3% → 1e-3 → 1e-6 → 1e-12).
    for _ in 0..3 {
        let y2 = y * y;
        y -= (y2 * y - v) / (3.0 * y2);
    }
    // v = 0 converges towards 0 without reaching it.
    if v > 0.0 { y } else { 0.0 }
}

/// `log2(x)` for normal positive `x`.
#[inline(always)]
fn log2(x: f32) -> f32 {
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000); // in [1, 2)
    // Centre the mantissa on 1 (in [√½, √2)) so the series below converges fast.
    if m > std::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    // ln m = 2 atanh t with t = (m − 1)/(m + 1), |t| ≤ 0.172: odd series to t⁹.
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let series = 1.0 + t2 * (1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (1.0 / 7.0 + t2 * (1.0 / 9.0))));
    e as f32 + 2.0 * t * series * std::f32::consts::LOG2_E
}

/// `2^z` for `z` in [−126, 127].
#[inline(always)]
fn exp2(z: f32) -> f32 {
    let z = z.clamp(-126.0, 127.0);
    // n = floor(z) without a libm call: truncate, then step down for negative fractions.
    let mut n = z as i32;
    if n as f32 > z {
        n -= 1;
    }
    // 2^f for f in [0, 1): e^((f − ½) ln 2) by Taylor to degree 6 (error < 2e-8), times √2.
    let g = (z - n as f32 - 0.5) * std::f32::consts::LN_2;
    let p = 1.0
        + g * (1.0
            + g * (1.0 / 2.0 + g * (1.0 / 6.0 + g * (1.0 / 24.0 + g * (1.0 / 120.0 + g * (1.0 / 720.0))))));
    p * std::f32::consts::SQRT_2 * f32::from_bits(((n + 127) as u32) << 23)
}

/// `x^y` for `x ≥ 0`, `y ≥ 0` (subnormal `x` counts as 0); `0^0 = 1` like `powf`.
#[inline(always)]
pub(crate) fn pow(x: f32, y: f32) -> f32 {
    let r = exp2(y * log2(x.max(f32::MIN_POSITIVE)));
    if y == 0.0 {
        1.0
    } else if x >= f32::MIN_POSITIVE {
        r
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f32, b: f32) -> f32 {
        if b == 0.0 { a.abs() } else { ((a - b) / b).abs() }
    }

    /// Logarithmically spaced samples of [lo, hi] and a few exact values.
    fn samples(lo: f32, hi: f32) -> impl Iterator<Item = f32> {
        let n = 100_000;
        (0..=n).map(move |i| lo * (hi / lo).powf(i as f32 / n as f32)).chain([lo, hi, 1.0, 0.5, 0.25])
    }

    #[test]
    fn cbrt_matches_libm() {
        // FLIP takes cube roots of XYZ / white in (0.0088, 1.01].
        let worst = samples(1e-3, 2.0).map(|v| rel(cbrt(v), v.cbrt())).fold(0.0, f32::max);
        assert!(worst < 3e-7, "{worst}");
        assert_eq!(cbrt(0.0), 0.0);
    }

    #[test]
    fn pow_matches_libm() {
        let mut worst = 0.0f32;
        for y in [0.0, 0.05, 0.3, 0.5, 0.7, 0.95, 1.0] {
            for x in samples(1e-30, 400.0) {
                worst = worst.max(rel(pow(x, y), x.powf(y)));
            }
        }
        // Mostly the rounding of y · log2(x) to f32: 1e-5 relative at x = 1e-30.
        assert!(worst < 1e-5, "{worst}");
        assert_eq!(pow(0.0, 0.7), 0.0);
        assert_eq!(pow(0.0, 0.0), 1.0);
        assert_eq!(pow(1e-40, 0.5), 0.0);
    }
}
