//! `KHR_materials_transmission` read as coverage: a surface that transmits a fraction t of the
//! light is met by a fraction 1 − t of the rays (alpha blending, which the ray-traced passes and
//! the reference path tracer read as stochastic coverage). What that keeps: light through glass,
//! unbent, at the right strength for a thin, clear, untinted pane seen head-on. What it loses,
//! said in a data-loss warning: the transmitted light's tint (the base colour), the glass's
//! Fresnel reflection over the transmitted part, refraction, roughness of the transmission, and
//! the transmission texture. Before, a transmissive material was opaque: ToyCar's glass dome and
//! the LightsPunctualLamp's shade were solid grey, and closed ToyCar's cabin to the sky.

use kiln_format::sections::{AlphaMode, GpuMaterial};

use super::Importer;
use crate::exit::CliResult;

impl Importer<'_> {
    /// Folds the transmission factor into `gpu`'s alpha (blending where the material was
    /// opaque); returns the alpha mode the material has then.
    pub(super) fn transmission_as_coverage(
        &mut self,
        at: &str,
        t: &::gltf::material::Transmission<'_>,
        alpha: AlphaMode,
        gpu: &mut GpuMaterial,
    ) -> CliResult<AlphaMode> {
        let [factor] = self.physical(
            at,
            "KHR_materials_transmission.transmissionFactor",
            [t.transmission_factor()],
            0.0,
            1.0,
        )?;
        if t.transmission_texture().is_some() {
            self.scene.warn(format!(
                "{at}: KHR_materials_transmission's transmissionTexture is not applied (the factor alone is)"
            ));
        }
        if factor == 0.0 {
            return Ok(alpha);
        }
        let mode = match alpha {
            // glTF ignores an opaque material's alpha: coverage is the transmission's alone.
            AlphaMode::Opaque => {
                gpu.base_color[3] = 1.0 - factor;
                AlphaMode::Blend
            }
            AlphaMode::Blend => {
                gpu.base_color[3] *= 1.0 - factor;
                AlphaMode::Blend
            }
            AlphaMode::Mask => {
                self.scene.warn(format!(
                    "{at}: KHR_materials_transmission (factor {factor}) on an alpha-masked material is not \
                     applied: the mask keeps its alpha"
                ));
                return Ok(alpha);
            }
        };
        self.scene.warn(format!(
            "{at}: KHR_materials_transmission (factor {factor}) is read as coverage {}: light passes \
             unbent and untinted, without the glass's reflection over it",
            1.0 - factor
        ));
        Ok(mode)
    }
}
