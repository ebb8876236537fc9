//! Denoising of the ray-traced signals: what filters the one-sample-per-pixel estimates of the
//! ray-traced passes before the composition reads them.

use super::techniques;

techniques! {
    /// Denoising of the ray-traced signals.
    Denoise for Denoise, default none::Off;
    none => Off,
    svgf => Svgf,
}
