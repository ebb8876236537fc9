//! A chart axis, linear or logarithmic, with its own tick choice: 1-2-5 steps on a linear axis,
//! 1-2-5 within each decade on a logarithmic one (plotters' own log axis labels every integer
//! multiple, which crowds the labels).

use std::ops::Range;

use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};

/// One axis: `lo..hi` in data units, both finite, `lo < hi`, and `lo > 0` when logarithmic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Axis {
    pub lo: f64,
    pub hi: f64,
    pub log: bool,
}

impl Axis {
    /// A linear axis; an empty or inverted range is widened so that mapping never divides by 0.
    pub fn linear(lo: f64, hi: f64) -> Axis {
        let hi = if hi > lo { hi } else { lo + lo.abs().max(1.0) };
        Axis { lo, hi, log: false }
    }

    /// A logarithmic axis (`0 < lo < hi`).
    pub fn log(lo: f64, hi: f64) -> Axis {
        debug_assert!(lo > 0.0 && hi > lo);
        Axis { lo, hi, log: true }
    }

    /// Where `v` lies along the axis, 0 at `lo` and 1 at `hi`.
    pub fn fraction(&self, v: f64) -> f64 {
        if self.log {
            (v / self.lo).ln() / (self.hi / self.lo).ln()
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }

    /// The ticks to label, at most about `n`.
    fn bold(&self, n: usize) -> Vec<f64> {
        let n = n.max(2);
        if self.log {
            let decades = (self.hi / self.lo).log10();
            let mantissas: &[f64] = if decades * 3.0 <= n as f64 {
                &[1.0, 2.0, 5.0]
            } else if decades <= n as f64 {
                &[1.0]
            } else {
                // Every k-th power of ten.
                let k = (decades / n as f64).ceil();
                return self.decades().filter(|d| d.rem_euclid(k) == 0.0).map(|d| 10f64.powf(d)).collect();
            };
            let ticks = self.log_ticks(mantissas);
            if ticks.len() >= 2 {
                return ticks;
            }
            // Less than a decade with too few 1-2-5 ticks: fall back to linear steps.
            return linear_ticks(self.lo, self.hi, n);
        }
        linear_ticks(self.lo, self.hi, n)
    }

    /// The ticks of the light grid lines: the labelled ones and finer ones between.
    fn light(&self, n: usize) -> Vec<f64> {
        let bold = self.bold(10);
        let mut all = if self.log && self.decades().count() <= 8 {
            self.log_ticks(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
        } else if self.log {
            bold.clone()
        } else {
            let step = if bold.len() >= 2 { (bold[1] - bold[0]) / 5.0 } else { (self.hi - self.lo) / 10.0 };
            let first = (self.lo / step).ceil() as i64;
            let last = (self.hi / step).floor() as i64;
            (first..=last).map(|i| i as f64 * step).collect()
        };
        if all.len() > n.max(bold.len()) {
            all = bold;
        }
        all
    }

    /// The powers of ten (as exponents) that can hold ticks in range.
    fn decades(&self) -> impl Iterator<Item = f64> {
        let (a, b) = (self.lo.log10().floor(), self.hi.log10().ceil());
        let count = if b >= a { (b - a) as i64 + 1 } else { 0 };
        (0..count.min(700)).map(move |i| a + i as f64)
    }

    fn log_ticks(&self, mantissas: &[f64]) -> Vec<f64> {
        let mut out = Vec::new();
        for d in self.decades() {
            for m in mantissas {
                // Parse the decimal so that 0.3 is 0.3, not 3 * 0.1.
                let v: f64 = format!("{m}e{d}").parse().unwrap_or(m * 10f64.powf(d));
                if v >= self.lo * (1.0 - 1e-9) && v <= self.hi * (1.0 + 1e-9) {
                    out.push(v);
                }
            }
        }
        out
    }
}

/// Multiples of a 1-2-5 step in `lo..=hi`, about `n` of them at most.
fn linear_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let raw = (hi - lo) / n as f64;
    if !(raw > 0.0) || !raw.is_finite() {
        return vec![lo];
    }
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * mag).find(|s| *s >= raw).unwrap_or(10.0 * mag);
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last).map(|i| i as f64 * step).collect()
}

/// A tick label: short, no float noise (0.30000000000000004 is "0.3"), scientific for the very
/// large and small.
pub(crate) fn format_number(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-4..1e6).contains(&a) {
        let s = format!("{v:.3e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        return format!("{}e{e}", trim_zeros(m));
    }
    // Six significant digits.
    let decimals = (5 - a.log10().floor() as i32).clamp(0, 10) as usize;
    trim_zeros(&format!("{v:.decimals$}")).to_string()
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.') } else { s }
}

impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let f = self.fraction(*value);
        let px = limit.0 as f64 + f * (limit.1 - limit.0) as f64;
        // Far outside (or NaN): clamp well beyond the area rather than wrap.
        px.clamp(-1e6, 1e6).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light(hint.max_num_points())
        } else {
            self.bold(hint.max_num_points())
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format_ext(&self, value: &f64) -> String {
        format_number(*value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers() {
        assert_eq!(format_number(0.1 + 0.2), "0.3");
        assert_eq!(format_number(20.0), "20");
        assert_eq!(format_number(0.0125), "0.0125");
        assert_eq!(format_number(2e-6), "2e-6");
        assert_eq!(format_number(1234567.0), "1.235e6");
    }

    #[test]
    fn ticks() {
        assert_eq!(linear_ticks(0.0, 1.0, 5), vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]);
        let log = Axis::log(0.3, 40.0);
        assert_eq!(log.bold(10), vec![0.5, 1.0, 2.0, 5.0, 10.0, 20.0]);
        assert!(Axis::log(1e-3, 1e9).bold(10).len() <= 13);
        assert_eq!(Axis::linear(2.0, 2.0), Axis { lo: 2.0, hi: 4.0, log: false });
    }
}
