//! `--shadows shadowmap`: the compiler's baked shadow maps (PCF; PCSS for rect lights), read by
//! the direct-light pass.

use crate::render::techniques::{Knobs, Needs, Registered, Technique};

/// The compiler's baked shadow maps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ShadowMap;

impl Registered for ShadowMap {
    const NAME: &'static str = "shadowmap";
    const HELP: &'static str = "the compiler's baked shadow maps (PCF; PCSS for rect lights)";

    fn new(_: &Knobs) -> Result<ShadowMap, String> {
        Ok(ShadowMap)
    }
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
