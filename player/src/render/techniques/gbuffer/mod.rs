//! How the G-buffer is made.

use super::techniques;

techniques! {
    /// How the G-buffer is made. The visibility buffer by default: on the GPU machine (H200,
    /// 1600 × 900) it halves the default frame (pica_pica 2.27 → 1.00 ms, ToyCar 2.36 → 1.69,
    /// LightsPunctualLamp 1.48 → 0.93, the demo 1.71 → 0.71) and shows the first frame as soon
    /// (docs/benchmarks/gbuffer-default/); both give the same image.
    GBuffer for GBuffer, default visibility::Visibility;
    raster => Raster,
    visibility => Visibility,
}
