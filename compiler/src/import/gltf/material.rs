//! A glTF material and its textures into the scene's material and texture records: factors
//! clamped into their physical ranges, the material extensions kiln reads (`specular.rs`,
//! `clearcoat.rs`, `transmission.rs`), one texture-coordinate mapping per material.

use kiln_format::manifest::Wrap;
use kiln_format::sections::{AlphaMode, GpuMaterial, MATERIAL_SLOTS, MaterialFlags, NO_TEXTURE};

use super::uri::{load_uri, short};
use super::{Importer, UvMapping};
use crate::exit::{CliError, CliResult};
use crate::import::files::ReadError;
use crate::import::images::TextureRequest;
use crate::ir::{Material, TextureRole};

impl Importer<'_> {
    pub(super) fn material(&mut self, m: ::gltf::Material) -> CliResult<u32> {
        if let Some(&i) = self.materials.get(&m.index()) {
            return Ok(i);
        }
        let name = match (m.index(), m.name()) {
            (_, Some(n)) => n.to_string(),
            (Some(i), None) => format!("material{i}"),
            (None, None) => "default".to_string(),
        };
        let pbr = m.pbr_metallic_roughness();
        let at = format!("{}: material '{name}'", self.file);
        // Factors outside their physical range (glTF 2.0's, and ≥ 0 for emission) are clamped
        // with a warning naming the field; a non-finite one is refused (JSON has no NaN and
        // serde_json refuses a number past f32's range, so only a product can overflow).
        let pbr_field = |f: &str| format!("pbrMetallicRoughness.{f}");
        let base_color =
            self.physical(&at, &pbr_field("baseColorFactor"), pbr.base_color_factor(), 0.0, 1.0)?;
        let [metallic] =
            self.physical(&at, &pbr_field("metallicFactor"), [pbr.metallic_factor()], 0.0, 1.0)?;
        let [roughness] =
            self.physical(&at, &pbr_field("roughnessFactor"), [pbr.roughness_factor()], 0.0, 1.0)?;
        let emissive = self.physical(&at, "emissiveFactor", m.emissive_factor(), 0.0, f32::INFINITY)?;
        let [strength] = self.physical(
            &at,
            "KHR_materials_emissive_strength.emissiveStrength",
            [m.emissive_strength().unwrap_or(1.0)],
            0.0,
            f32::INFINITY,
        )?;
        let mut gpu = GpuMaterial {
            base_color,
            emission: emissive.map(|e| e * strength),
            metallic,
            roughness,
            alpha_cutoff: m.alpha_cutoff().unwrap_or(0.5),
            normal_scale: m.normal_texture().map_or(1.0, |t| t.scale()),
            occlusion_strength: m.occlusion_texture().map_or(1.0, |t| t.strength()),
            ..GpuMaterial::default()
        };
        if !gpu.emission.iter().all(|v| v.is_finite()) {
            return Err(CliError::input(format!(
                "{at}: emissiveFactor {emissive:?} × KHR_materials_emissive_strength.emissiveStrength \
                 {strength:?} is not finite"
            )));
        }
        for (field, v) in [
            ("alphaCutoff", gpu.alpha_cutoff),
            ("normalTexture.scale", gpu.normal_scale),
            ("occlusionTexture.strength", gpu.occlusion_strength),
        ] {
            self.physical(&at, field, [v], f32::NEG_INFINITY, f32::INFINITY)?;
        }
        let alpha = match m.alpha_mode() {
            ::gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            ::gltf::material::AlphaMode::Mask => AlphaMode::Mask,
            ::gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        gpu.flags = (alpha as u32) << MaterialFlags::ALPHA_MODE_SHIFT;
        if m.double_sided() {
            gpu.flags |= MaterialFlags::DOUBLE_SIDED;
        }
        self.dielectric_reflectance(&at, &m, &mut gpu)?;
        let [coat, coat_roughness] = self.clearcoat(&at, &m, &mut gpu)?;
        let transmission = self.transmission(&at, &m, &mut gpu)?;
        // Every texture of the material reads one set of coordinates through one transform (the
        // format stores one set per vertex, with the transform baked in); the first texture's
        // mapping is that of all, and a texture mapped otherwise is named in a warning.
        fn info(i: ::gltf::texture::Info<'_>) -> (::gltf::Texture<'_>, UvMapping) {
            (i.texture(), UvMapping::of(i.tex_coord(), i.texture_transform()))
        }
        let refs = [
            pbr.base_color_texture().map(info),
            pbr.metallic_roughness_texture().map(info),
            m.normal_texture().map(|i| (i.texture(), UvMapping::of(i.tex_coord(), None))),
            m.occlusion_texture().map(|i| (i.texture(), UvMapping::of(i.tex_coord(), None))),
            m.emissive_texture().map(info),
            coat,
            coat_roughness,
            transmission,
        ];
        let mapping = refs.iter().flatten().map(|(_, u)| *u).next().unwrap_or(UvMapping::of(0, None));
        for (t, u) in refs.iter().flatten() {
            if u.set != mapping.set || (u.matrix != mapping.matrix && u.matrix != UvMapping::IDENTITY) {
                self.scene.warn(format!(
                    "{}: material '{name}' maps texture {} with other texture coordinates or another \
                     transform than its first texture; it is sampled with the first's (TEXCOORD_{})",
                    self.file,
                    t.index(),
                    mapping.set
                ));
            }
        }
        let roles = [
            TextureRole::Color,
            TextureRole::Data,
            TextureRole::Normal,
            TextureRole::Data,
            TextureRole::Color,
            TextureRole::Data,
            TextureRole::Data,
            TextureRole::Data,
        ];
        let mut slots = [NO_TEXTURE; MATERIAL_SLOTS];
        for (k, r) in refs.into_iter().enumerate() {
            if let Some((t, _)) = r {
                slots[k] = self.texture(t, roles[k]);
            }
        }
        [
            gpu.base_color_texture,
            gpu.metallic_roughness_texture,
            gpu.normal_texture,
            gpu.occlusion_texture,
            gpu.emissive_texture,
            gpu.clearcoat_texture,
            gpu.clearcoat_roughness_texture,
            gpu.transmission_texture,
        ] = slots;
        let index = self.scene.materials.len() as u32;
        self.uv_mappings.insert(index, mapping);
        self.scene.materials.push(Material { name, gpu });
        self.materials.insert(m.index(), index);
        Ok(index)
    }

    /// `v`, the value of material field `field` (of the material `at` names), clamped into
    /// [`lo`, `hi`] with a warning (class data-loss) when it lies outside; an error when it is
    /// not finite (JSON has no NaN, but a number past f32's range reads as infinite).
    pub(super) fn physical<const N: usize>(
        &mut self,
        at: &str,
        field: &str,
        v: [f32; N],
        lo: f32,
        hi: f32,
    ) -> CliResult<[f32; N]> {
        let show = |v: &[f32; N]| if N == 1 { v[0].to_string() } else { format!("{v:?}") };
        if !v.iter().all(|x| x.is_finite()) {
            return Err(CliError::input(format!("{at}: {field} is {}, not a finite number", show(&v))));
        }
        let clamped = v.map(|x| x.clamp(lo, hi));
        if clamped != v {
            let range = match (lo, hi) {
                (0.0, f32::INFINITY) => "negative".to_string(),
                (_, f32::INFINITY) => format!("below {lo}"),
                _ => format!("outside [{lo}, {hi}]"),
            };
            self.scene.warn(format!("{at}: {field} {} is {range}; clamped to {}", show(&v), show(&clamped)));
        }
        Ok(clamped)
    }

    pub(super) fn texture(&mut self, t: ::gltf::Texture, role: TextureRole) -> u32 {
        if let Some(&i) = self.textures.get(&(t.index(), role)) {
            return i;
        }
        let Some(img) = t.source() else {
            self.scene.warn(format!(
                "{}: texture {} has no image (an extension kiln does not read may supply it); the material \
                 samples no texture there",
                self.file,
                t.index()
            ));
            return NO_TEXTURE;
        };
        let name = img.name().map(str::to_string).unwrap_or_else(|| match img.source() {
            ::gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => uri.to_string(),
            _ => format!("image{}", img.index()),
        });
        let bytes = self.image_bytes(&img);
        let s = t.sampler();
        let wrap = |w: ::gltf::texture::WrappingMode| match w {
            ::gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
            ::gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            ::gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        };
        let index = (self.scene.textures.len() + self.requests.len()) as u32;
        self.requests.push(TextureRequest {
            name,
            bytes,
            role,
            wrap_u: wrap(s.wrap_s()),
            wrap_v: wrap(s.wrap_t()),
            mag_linear: s.mag_filter() != Some(::gltf::texture::MagFilter::Nearest),
        });
        self.textures.insert((t.index(), role), index);
        index
    }

    /// The encoded bytes of `img`: its buffer view's, or its URI's (data, or a file read within
    /// the confinement: a file outside it is also recorded in `escapes`, which fail the import).
    pub(super) fn image_bytes(&mut self, img: &::gltf::Image) -> Result<Vec<u8>, String> {
        match img.source() {
            ::gltf::image::Source::View { view, .. } => {
                let buf = &self.buffers[view.buffer().index()];
                buf.get(view.offset()..view.offset().saturating_add(view.length()))
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| format!("buffer view {} runs past the end of its buffer", view.index()))
            }
            ::gltf::image::Source::Uri { uri, .. } => {
                let what = format!("image {} ('{}')", img.index(), short(uri));
                load_uri(uri, &self.base, &mut self.scene.inputs, &what).map_err(|e| match e {
                    ReadError::Confined(e) => {
                        self.escapes.push(e.clone());
                        e
                    }
                    ReadError::Unreadable(e) => e,
                })
            }
        }
    }
}
