//! How the passes that read textures from the texel buffer (the visibility-buffer resolve, the
//! ray-traced passes, the reference path tracer) decode them: a per-file choice, made once from
//! the texture table the shaders read, and given to those pipelines as the specialization
//! constant `TEXELS_BC` of `shaders/common/textures.glsl`.
//!
//! The GLSL BC decoders are large, and each place a shader samples a texture inlines a copy;
//! compiled for every file they made lavapipe's pipeline compiles take minutes. With `TEXELS_BC`
//! false the driver drops them before compiling, so only a file that has BC textures pays for
//! them.

use kiln_format::gpu::GpuTexture;
use kiln_format::sections::PixelFormat;

/// The `constant_id` of `TEXELS_BC` in `shaders/common/textures.glsl`.
pub const TEXELS_BC_ID: u32 = 0;

/// What the texel buffer holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TexelDecode {
    /// RGBA8 words only: the BC decoders are compiled out.
    #[default]
    Rgba8,
    /// Some textures are BC blocks: the decoders are compiled in.
    Bc,
}

impl TexelDecode {
    /// The decode a texture table needs: [`TexelDecode::Bc`] when any texture's format (the
    /// bits the shaders read, [`GpuTexture::pixel_format`]) is not RGBA8.
    pub fn of(textures: &[GpuTexture]) -> TexelDecode {
        if textures.iter().any(|t| t.pixel_format() != PixelFormat::Rgba8) {
            TexelDecode::Bc
        } else {
            TexelDecode::Rgba8
        }
    }

    /// The specialization constants of a pipeline that reads the texel buffer, by
    /// `constant_id` (the pipeline cache keys on them).
    pub fn constants(self) -> [u32; 1] {
        let mut c = [0; 1];
        c[TEXELS_BC_ID as usize] = (self == TexelDecode::Bc) as u32;
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::spirv;
    use kiln_format::gpu::TextureFlags;

    fn texture(format: u32) -> GpuTexture {
        GpuTexture {
            offset: 0,
            width: 4,
            height: 4,
            flags: format << TextureFlags::FORMAT_SHIFT
                | TextureFlags::SRGB
                | 3 << TextureFlags::LEVELS_SHIFT,
        }
    }

    #[test]
    fn files_without_bc_textures_compile_the_decoders_out() {
        for table in [vec![], vec![texture(0)], vec![texture(0), texture(0)]] {
            assert_eq!(TexelDecode::of(&table), TexelDecode::Rgba8);
        }
        assert_eq!(TexelDecode::Rgba8.constants(), [0]);
    }

    #[test]
    fn one_bc_texture_compiles_the_decoders_in() {
        for format in 1..=3 {
            assert_eq!(TexelDecode::of(&[texture(0), texture(format)]), TexelDecode::Bc, "format {format}");
        }
        assert_eq!(TexelDecode::Bc.constants(), [1]);
    }

    /// Every shader with the BC decoders in its SPIR-V declares `TEXELS_BC` with the id the
    /// player sets, as a bool that defaults to false (so a pipeline built without the constant
    /// compiles the decoders out rather than in by accident), and no shader declares another
    /// specialization constant that the player's constants would set (but the direct pass,
    /// whose own constants it sets).
    #[test]
    fn shaders_with_the_decoders_declare_the_constant() {
        let mut decoding = 0;
        for source in spirv::sources().unwrap() {
            let bytes = std::fs::read(spirv::shader_dir().join(format!("{source}.spv"))).unwrap();
            let bytes = bytes.as_slice();
            let source = source.as_str();
            let (consts, numbers, decoders) = spec_constants(bytes);
            if source == "reference/pathtrace.comp" {
                // TEXELS_BC, HAS_MEDIA and the workgroup's depth (STREAMS), all set by
                // passes/pathtrace.rs.
                let mut consts = consts;
                consts.sort();
                assert_eq!(consts, [(TEXELS_BC_ID, false), (1, true)], "{source}");
                assert_eq!(numbers, [2], "{source}");
                decoding += 1;
                continue;
            }
            assert!(numbers.is_empty(), "{source}: numeric specialization constants {numbers:?}");
            if decoders {
                assert_eq!(consts, [(TEXELS_BC_ID, false)], "{source}: TEXELS_BC");
                decoding += 1;
            } else if source == "lighting/direct.comp" {
                // The direct pass's own constants (passes/direct.rs checks their names).
                let ids: Vec<(u32, bool)> = (1..=crate::render::passes::direct::SPEC_INPUTS.len() as u32)
                    .map(|id| (id, true))
                    .collect();
                let mut consts = consts;
                consts.sort();
                assert_eq!(consts, ids, "{source}");
            } else {
                assert!(consts.iter().all(|&c| c == (TEXELS_BC_ID, false)), "{source}: {consts:?}");
            }
        }
        assert!(decoding >= 10, "only {decoding} shaders have the BC decoders");
    }

    /// (SpecId, default) of every boolean specialization constant of a SPIR-V module, the
    /// SpecIds of its numeric ones, and whether it has the BC7 decoder (the first word of
    /// `BC7_PARTITION` in `shaders/common/bc.glsl` is one of its constants).
    fn spec_constants(bytes: &[u8]) -> (Vec<(u32, bool)>, Vec<u32>, bool) {
        let words: Vec<u32> =
            bytes.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect();
        let (mut ids, mut defaults) = (Vec::new(), std::collections::HashMap::new());
        let mut numbers = std::collections::HashSet::new();
        let mut decoder = false;
        let mut i = 5;
        while i < words.len() {
            let (count, op) = ((words[i] >> 16) as usize, words[i] & 0xffff);
            let w = &words[i..i + count];
            match op {
                // OpDecorate %target SpecId n
                71 if w[2] == 1 => ids.push((w[1], w[3])),
                // OpSpecConstantTrue / OpSpecConstantFalse %type %result
                48 | 49 => {
                    defaults.insert(w[2], op == 48);
                }
                // OpSpecConstant %type %result value (a number)
                50 => {
                    numbers.insert(w[2]);
                }
                // OpConstant %type %result value
                43 if w.len() == 4 && w[3] == 0x0f3f_cccc => decoder = true,
                _ => {}
            }
            i += count.max(1);
        }
        let (numeric, boolean): (Vec<_>, Vec<_>) =
            ids.into_iter().partition(|(target, _)| numbers.contains(target));
        let mut numeric: Vec<u32> = numeric.into_iter().map(|(_, id)| id).collect();
        // (glslc declares a workgroup size's constant twice: alone and inside gl_WorkGroupSize.)
        numeric.sort();
        numeric.dedup();
        (boolean.into_iter().map(|(target, id)| (id, defaults[&target])).collect(), numeric, decoder)
    }
}
