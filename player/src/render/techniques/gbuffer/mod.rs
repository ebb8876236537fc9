//! How the G-buffer is made.

use super::techniques;

techniques! {
    /// How the G-buffer is made.
    GBuffer for GBuffer, default raster::Raster;
    raster => Raster,
    visibility => Visibility,
}
