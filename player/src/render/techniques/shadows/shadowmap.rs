//! `--shadows shadowmap`: the compiler's baked shadow maps (PCF; PCSS for rect lights), read by
//! the direct-light pass.

use crate::render::techniques::{Needs, Technique, plain_technique};

plain_technique! {
    /// The compiler's baked shadow maps.
    ShadowMap,
    "shadowmap",
    "the compiler's baked shadow maps (PCF; PCSS for rect lights); emissive surfaces have none: --direct traces \
     their shadow rays through the BVH"
}

impl Technique for ShadowMap {
    fn needs(&self) -> Needs {
        Needs { shadow_maps: true, ..Needs::NONE }
    }

    fn warnings(&self, flag: &str, manifest: &kiln_format::Manifest, warnings: &mut Vec<String>) {
        if manifest.shadow_maps.is_empty() && !manifest.lights.is_empty() {
            warnings.push(format!(
                "{flag}: the file has no shadow maps (compiled with shadows skipped); lights are unshadowed"
            ));
        }
    }
}
