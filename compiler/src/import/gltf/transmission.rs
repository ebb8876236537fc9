//! `KHR_materials_transmission`: light passing through a surface (glass, a paper shade, a
//! film). The format stores the factor and its texture (format 1.9, FORMAT.md "Transmission");
//! the reference path tracer and the passes that trace rays shade it thin-walled, as the
//! extension does without `KHR_materials_volume`: the specular lobe mirrored through the surface,
//! tinted by the base colour, taking its light from the diffuse part. The raster frame draws
//! nothing through surfaces: it keeps their reflection and scales their diffuse light by 1 − t
//! (docs/compiler.md). The texture's R multiplies the factor.
//!
//! Before format 1.9 the factor was read as coverage (light passing unbent, untinted and
//! without the glass's reflection); an alpha-blended material's alpha still is coverage, apart
//! from its transmission.

use ::gltf::Texture;
use kiln_format::sections::GpuMaterial;

use super::{Importer, UvMapping};
use crate::exit::CliResult;

impl Importer<'_> {
    /// Reads material `m`'s transmission (if any) into `gpu`; returns the reference of its
    /// texture, for the caller to load and check with the others.
    pub(super) fn transmission<'m>(
        &mut self,
        at: &str,
        m: &::gltf::Material<'m>,
        gpu: &mut GpuMaterial,
    ) -> CliResult<Option<(Texture<'m>, UvMapping)>> {
        let Some(t) = m.transmission() else {
            return Ok(None);
        };
        let [factor] = self.physical(
            at,
            "KHR_materials_transmission.transmissionFactor",
            [t.transmission_factor()],
            0.0,
            1.0,
        )?;
        if factor == 0.0 {
            return Ok(None);
        }
        if gpu.diffuse_only() {
            // Not reachable from glTF today (diffuse-only is OBJ's Ks 0), kept honest anyway.
            self.scene
                .warn(format!("{at}: KHR_materials_transmission on a diffuse-only material is not applied"));
            return Ok(None);
        }
        gpu.transmission = factor;
        Ok(t.transmission_texture()
            .map(|i| (i.texture(), UvMapping::of(i.tex_coord(), i.texture_transform()))))
    }
}
