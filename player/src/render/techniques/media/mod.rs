//! Participating media.

use super::knobs::{Knob, number, whole};
use super::techniques;

techniques! {
    /// Participating media.
    Media for Media, default none::Off;
    none => Off,
    march => March,
    mitchell => Mitchell,
    sousa => Sousa,
    toth => Toth,
}

/// Samples along the way of the media techniques that take a fixed count (Mitchell, Tóth).
pub const MEDIA_SAMPLES: Knob = whole(number(
    "media-samples",
    "samples per pixel: mitchell, towards the light; toth, along the view ray (over an \
     interleaving block)",
    1.0,
    1024.0,
    60.0,
    &[18.0, 60.0, 100.0],
));

/// Resolution of the image-space god rays' first image.
pub const MEDIA_RES: Knob = super::knobs::choice(
    "media-res",
    "resolution of mitchell's occlusion image and sousa's depth map and first two blurs: \
     full, half or quarter of the screen's on each axis (read bilinearly: smoother shafts)",
    &["full", "half", "quarter"],
    2,
);

/// Warns, and says so, when the file has no medium for the technique chosen as `flag`.
fn no_medium(flag: &str, manifest: &kiln_format::Manifest, warnings: &mut Vec<String>) -> bool {
    let none = manifest.media.is_empty();
    if none {
        warnings.push(format!(
            "{flag}: the file has no participating medium (add a [[medium]] to the sidecar and recompile); it adds nothing"
        ));
    }
    none
}

/// Whether a light casts shadows (else no technique has shafts to shadow).
fn casters(manifest: &kiln_format::Manifest) -> bool {
    manifest.lights.iter().any(|l| l.casts_shadows)
}
