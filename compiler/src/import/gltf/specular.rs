//! `KHR_materials_ior` and `KHR_materials_specular`: the dielectric part's reflectance.
//!
//! glTF's core material reflects like a dielectric of index of refraction 1.5 (F0 = 0.04) with
//! Fresnel rising to 1 at grazing angles. The extensions set, per the Khronos specification,
//! F0 = min(((ior − 1)/(ior + 1))² · specularColorFactor, 1) · specularFactor and F90 =
//! specularFactor, which the format stores beside the material ([`GpuMaterial::set_dielectric`])
//! and every technique reads through Schlick's Fresnel. What is lost, said in a warning: the
//! `specularTexture` and `specularColorTexture` (the factors alone are applied), and, in the
//! raster G-buffer, F0's colour (its luminance is kept; the ray-traced passes and the reference
//! keep the colour).

use kiln_format::sections::GpuMaterial;

use super::Importer;
use crate::exit::CliResult;

/// The index of refraction glTF assumes without `KHR_materials_ior`.
const DEFAULT_IOR: f32 = 1.5;

impl Importer<'_> {
    /// Applies the material's `ior` and `specular` extensions (if any) to `gpu`.
    pub(super) fn dielectric_reflectance(
        &mut self,
        at: &str,
        m: &::gltf::Material<'_>,
        gpu: &mut GpuMaterial,
    ) -> CliResult {
        let (ior, specular) = (m.ior(), m.specular());
        if ior.is_none() && specular.is_none() {
            return Ok(());
        }
        let ior = match ior {
            // The specification allows 0 beside values of at least 1 (F0 = 1: a perfect mirror).
            Some(0.0) => 0.0,
            Some(ior) => self.physical(at, "KHR_materials_ior.ior", [ior], 1.0, f32::INFINITY)?[0],
            None => DEFAULT_IOR,
        };
        let (factor, color) = match &specular {
            Some(s) => {
                let [factor] = self.physical(
                    at,
                    "KHR_materials_specular.specularFactor",
                    [s.specular_factor()],
                    0.0,
                    1.0,
                )?;
                let color = self.physical(
                    at,
                    "KHR_materials_specular.specularColorFactor",
                    s.specular_color_factor(),
                    0.0,
                    f32::INFINITY,
                )?;
                let textures = [
                    ("specularTexture", s.specular_texture().is_some()),
                    ("specularColorTexture", s.specular_color_texture().is_some()),
                ];
                for (name, _) in textures.iter().filter(|(_, present)| *present) {
                    self.scene.warn(format!(
                        "{at}: KHR_materials_specular's {name} is not applied (the factors alone are)"
                    ));
                }
                (factor, color)
            }
            None => (1.0, [1.0; 3]),
        };
        let r = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let f0 = color.map(|c| (r * c).min(1.0) * factor);
        gpu.set_dielectric(f0, factor);
        Ok(())
    }
}
