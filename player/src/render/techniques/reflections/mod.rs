//! Specular reflections beyond the split-sum ambient.

use super::techniques;

techniques! {
    /// Specular reflections beyond the split-sum ambient.
    Reflections for Reflections, default none::Off;
    none => Off,
    rt => Rt,
    ssr => Ssr,
}
