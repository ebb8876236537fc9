//! Texture sections (`TEXL`): pixel formats, the version-2 header, and mip-chain sizes.
//!
//! Version 1 (format 1.0, 1.1) is a bare RGBA8 mip chain. Version 2 (format 1.2) starts with a
//! 16-byte [`TextureHeader`] naming the pixel format (RGBA8 or a BC block format) and a channel
//! swizzle, then the mip chain in that format. The header is 16 bytes so that the levels stay
//! 16-byte aligned, which is what a GPU copy of BC7 or BC5 blocks requires.

use bytemuck::{Pod, Zeroable};

use crate::error::{FormatError, Result};

/// Bytes of the version-2 header.
pub const TEXTURE_HEADER_BYTES: usize = 16;

/// How the texels of a `TEXL` section are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum PixelFormat {
    /// 4 bytes per texel, R, G, B, A.
    Rgba8 = 0,
    /// BC7: 16-byte blocks of 4×4 texels, RGBA (sRGB or linear by the manifest's colour space).
    Bc7 = 1,
    /// BC5: 16-byte blocks of 4×4 texels, two channels (R, G), linear.
    Bc5 = 2,
    /// BC4: 8-byte blocks of 4×4 texels, one channel (R), linear.
    Bc4 = 3,
}

impl PixelFormat {
    /// Every format, in number order.
    pub const ALL: [PixelFormat; 4] =
        [PixelFormat::Rgba8, PixelFormat::Bc7, PixelFormat::Bc5, PixelFormat::Bc4];

    /// The format with this stored number.
    pub fn from_u32(v: u32) -> Option<PixelFormat> {
        PixelFormat::ALL.into_iter().find(|f| *f as u32 == v)
    }

    /// Name for messages and reports.
    pub fn name(self) -> &'static str {
        match self {
            PixelFormat::Rgba8 => "rgba8",
            PixelFormat::Bc7 => "bc7",
            PixelFormat::Bc5 => "bc5",
            PixelFormat::Bc4 => "bc4",
        }
    }

    /// Whether texels are stored in 4×4 blocks.
    pub fn is_block_compressed(self) -> bool {
        self != PixelFormat::Rgba8
    }

    /// Texels per block side (1 for RGBA8).
    pub fn block_dim(self) -> u32 {
        if self.is_block_compressed() { 4 } else { 1 }
    }

    /// Bytes per block (per texel for RGBA8).
    pub fn block_bytes(self) -> u32 {
        match self {
            PixelFormat::Rgba8 => 4,
            PixelFormat::Bc7 | PixelFormat::Bc5 => 16,
            PixelFormat::Bc4 => 8,
        }
    }

    /// Stored channels (R; R, G; or R, G, B, A).
    pub fn channels(self) -> u8 {
        match self {
            PixelFormat::Rgba8 | PixelFormat::Bc7 => 4,
            PixelFormat::Bc5 => 2,
            PixelFormat::Bc4 => 1,
        }
    }

    /// Bytes of one level of `width × height` texels (blocks rounded up), `None` on overflow.
    pub fn level_bytes(self, width: u32, height: u32) -> Option<u64> {
        let d = self.block_dim();
        let bw = width.div_ceil(d) as u64;
        let bh = height.div_ceil(d) as u64;
        bw.checked_mul(bh)?.checked_mul(self.block_bytes() as u64)
    }

    /// Bytes of a full mip chain, or `None` if the description is impossible (zero size, wrong
    /// level count, overflow).
    pub fn chain_bytes(self, width: u32, height: u32, levels: u32) -> Option<u64> {
        if width == 0 || height == 0 || levels != crate::scene::mip_levels(width, height) {
            return None;
        }
        let mut total: u64 = 0;
        for l in 0..levels {
            total = total.checked_add(self.level_bytes((width >> l).max(1), (height >> l).max(1))?)?;
        }
        Some(total)
    }
}

/// Swizzle value: what a sampled channel returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Swizzle {
    /// Stored channel R.
    R = 0,
    /// Stored channel G.
    G = 1,
    /// Stored channel B.
    B = 2,
    /// Stored channel A.
    A = 3,
    /// Constant 0.
    Zero = 4,
    /// Constant 1.
    One = 5,
}

impl Swizzle {
    /// The identity swizzle (R, G, B, A).
    pub const IDENTITY: [Swizzle; 4] = [Swizzle::R, Swizzle::G, Swizzle::B, Swizzle::A];

    /// The swizzle with this stored number.
    pub fn from_u8(v: u8) -> Option<Swizzle> {
        [Swizzle::R, Swizzle::G, Swizzle::B, Swizzle::A, Swizzle::Zero, Swizzle::One]
            .into_iter()
            .find(|s| *s as u8 == v)
    }
}

/// The version-2 header of a `TEXL` section (16 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
#[repr(C)]
pub struct TextureHeader {
    /// [`PixelFormat`] number.
    pub format: u32,
    /// [`Swizzle`] of the sampled R, G, B, A.
    pub swizzle: [u8; 4],
    /// Zero.
    pub reserved: [u32; 2],
}

const _: () = assert!(size_of::<TextureHeader>() == TEXTURE_HEADER_BYTES);

/// A texture's stored texels, decoded from its section.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TextureData<'a> {
    /// Pixel format of `levels`.
    pub format: PixelFormat,
    /// What the sampled R, G, B, A return.
    pub swizzle: [Swizzle; 4],
    /// The mip chain, level 0 first, each level's blocks (texels) in rows top to bottom.
    pub levels: &'a [u8],
}

impl TextureData<'_> {
    /// The bytes of each level, level 0 first, for a `width × height` texture.
    pub fn level_slices(&self, width: u32, height: u32, mip_levels: u32) -> Vec<&[u8]> {
        let mut out = Vec::with_capacity(mip_levels as usize);
        let mut offset = 0usize;
        for l in 0..mip_levels {
            // Sizes were checked against the section length when the data was decoded.
            let n = self.format.level_bytes((width >> l).max(1), (height >> l).max(1)).unwrap_or(0) as usize;
            out.push(&self.levels[offset.min(self.levels.len())..(offset + n).min(self.levels.len())]);
            offset += n;
        }
        out
    }
}

/// The bytes of a version-2 `TEXL` section: header, then the mip chain.
pub fn encode_texture(format: PixelFormat, swizzle: [Swizzle; 4], levels: &[u8]) -> Vec<u8> {
    let header = TextureHeader { format: format as u32, swizzle: swizzle.map(|s| s as u8), reserved: [0; 2] };
    let mut out = Vec::with_capacity(TEXTURE_HEADER_BYTES + levels.len());
    out.extend_from_slice(bytemuck::bytes_of(&header));
    out.extend_from_slice(levels);
    out
}

/// Section lengths a version-2 `TEXL` of this size may have (one per distinct chain size), for
/// checks from the table before the bytes are read.
pub fn possible_v2_lengths(width: u32, height: u32, levels: u32) -> Vec<u64> {
    let mut v: Vec<u64> = PixelFormat::ALL
        .iter()
        .filter_map(|f| f.chain_bytes(width, height, levels))
        .filter_map(|n| n.checked_add(TEXTURE_HEADER_BYTES as u64))
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// Decodes the bytes of a `TEXL` section of `version` for a texture of the given size and
/// colour space (`srgb`): checks the header, the format against the colour space, the swizzle
/// against the stored channels, and the length against the chain.
pub fn decode_texture(
    version: u16,
    bytes: &[u8],
    width: u32,
    height: u32,
    mip_levels: u32,
    srgb: bool,
) -> Result<TextureData<'_>> {
    let impossible = || {
        FormatError::invalid(format!(
            "texture of {width}x{height} with {mip_levels} mip levels is impossible (a full chain \
             has floor(log2(max(w, h))) + 1 levels)"
        ))
    };
    let (format, swizzle, levels) = match version {
        1 => (PixelFormat::Rgba8, Swizzle::IDENTITY, bytes),
        2 => {
            let Some(head) = bytes.get(..TEXTURE_HEADER_BYTES) else {
                return Err(FormatError::invalid(format!(
                    "texture section of {} bytes is shorter than its {TEXTURE_HEADER_BYTES}-byte header",
                    bytes.len()
                )));
            };
            let h: TextureHeader = bytemuck::pod_read_unaligned(head);
            let format = PixelFormat::from_u32(h.format).ok_or_else(|| {
                FormatError::invalid(format!("texture pixel format {} is unknown (0..=3 defined)", h.format))
            })?;
            if h.reserved != [0; 2] {
                return Err(FormatError::invalid("texture header's reserved bytes are not zero"));
            }
            let mut swizzle = [Swizzle::Zero; 4];
            for (c, &s) in h.swizzle.iter().enumerate() {
                swizzle[c] = Swizzle::from_u8(s).ok_or_else(|| {
                    FormatError::invalid(format!(
                        "texture swizzle {s} of channel {c} is unknown (0..=5 defined)"
                    ))
                })?;
                if s < 4 && s >= format.channels() {
                    return Err(FormatError::invalid(format!(
                        "texture swizzle of channel {c} reads stored channel {s}, but {} stores {}",
                        format.name(),
                        format.channels()
                    )));
                }
            }
            (format, swizzle, &bytes[TEXTURE_HEADER_BYTES..])
        }
        v => return Err(FormatError::invalid(format!("texture section version {v} is unknown"))),
    };
    if srgb && matches!(format, PixelFormat::Bc4 | PixelFormat::Bc5) {
        return Err(FormatError::invalid(format!(
            "texture is sRGB but stored as {}, which has no sRGB form",
            format.name()
        )));
    }
    let expected = format.chain_bytes(width, height, mip_levels).ok_or_else(impossible)?;
    if levels.len() as u64 != expected {
        return Err(FormatError::invalid(format!(
            "texture levels are {} bytes, a {width}x{height} {} mip chain needs {expected}",
            levels.len(),
            format.name()
        )));
    }
    Ok(TextureData { format, swizzle, levels })
}

/// Decodes one stored level to RGBA8 of its stored channels (missing ones 0, alpha 255), through
/// `bcdec_rs`, a decoder independent of the compiler's encoder and of the shaders'.
pub fn decode_level(format: PixelFormat, bytes: &[u8], width: u32, height: u32) -> Vec<u8> {
    if format == PixelFormat::Rgba8 {
        return bytes[..(width * height * 4) as usize].to_vec();
    }
    let (bw, bh) = (width.div_ceil(4) as usize, height.div_ceil(4) as usize);
    let bb = format.block_bytes() as usize;
    let mut out = vec![0u8; width as usize * height as usize * 4];
    for by in 0..bh {
        for bx in 0..bw {
            let block = &bytes[(by * bw + bx) * bb..][..bb];
            let mut px = [0u8; 64];
            match format {
                PixelFormat::Bc7 => bcdec_rs::bc7(block, &mut px, 16),
                PixelFormat::Bc5 => {
                    let mut rg = [0u8; 32];
                    bcdec_rs::bc5(block, &mut rg, 8, false);
                    for i in 0..16 {
                        px[i * 4..i * 4 + 4].copy_from_slice(&[rg[i * 2], rg[i * 2 + 1], 0, 255]);
                    }
                }
                PixelFormat::Bc4 => {
                    let mut r = [0u8; 16];
                    bcdec_rs::bc4(block, &mut r, 4, false);
                    for i in 0..16 {
                        px[i * 4..i * 4 + 4].copy_from_slice(&[r[i], 0, 0, 255]);
                    }
                }
                PixelFormat::Rgba8 => unreachable!(),
            }
            for y in 0..4 {
                for x in 0..4 {
                    let (tx, ty) = (bx * 4 + x, by * 4 + y);
                    if tx < width as usize && ty < height as usize {
                        let dst = (ty * width as usize + tx) * 4;
                        out[dst..dst + 4].copy_from_slice(&px[(y * 4 + x) * 4..][..4]);
                    }
                }
            }
        }
    }
    out
}

impl TextureData<'_> {
    /// The whole mip chain of a `width × height` texture as RGBA8 of its stored channels
    /// ([`decode_level`] level by level; a copy where it is RGBA8 already).
    pub fn decoded_chain(&self, width: u32, height: u32, mip_levels: u32) -> Vec<u8> {
        let mut out = Vec::new();
        for (l, level) in self.level_slices(width, height, mip_levels).into_iter().enumerate() {
            let (w, h) = ((width >> l).max(1), (height >> l).max(1));
            out.extend(decode_level(self.format, level, w, h));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_sizes_round_up_to_blocks() {
        // 5×3 is 2×1 blocks; 1×1 is one block.
        assert_eq!(PixelFormat::Bc7.level_bytes(5, 3), Some(32));
        assert_eq!(PixelFormat::Bc4.level_bytes(1, 1), Some(8));
        assert_eq!(PixelFormat::Rgba8.level_bytes(5, 3), Some(60));
        // 8×2: levels 8×2, 4×1, 2×1, 1×1 → 2 + 1 + 1 + 1 blocks of 16 bytes.
        assert_eq!(PixelFormat::Bc5.chain_bytes(8, 2, 4), Some(80));
        assert_eq!(PixelFormat::Bc5.chain_bytes(8, 2, 3), None);
    }

    #[test]
    fn decode_checks_header_and_length() {
        let chain = vec![0u8; 80];
        let ok =
            encode_texture(PixelFormat::Bc5, [Swizzle::Zero, Swizzle::R, Swizzle::G, Swizzle::One], &chain);
        let d = decode_texture(2, &ok, 8, 2, 4, false).unwrap();
        assert_eq!((d.format, d.levels.len()), (PixelFormat::Bc5, 80));
        assert_eq!(d.level_slices(8, 2, 4).iter().map(|l| l.len()).collect::<Vec<_>>(), [32, 16, 16, 16]);
        // One byte short, one too many.
        assert!(decode_texture(2, &ok[..ok.len() - 1], 8, 2, 4, false).is_err());
        let mut long = ok.clone();
        long.push(0);
        assert!(decode_texture(2, &long, 8, 2, 4, false).is_err());
        // Header cut short.
        assert!(decode_texture(2, &ok[..10], 8, 2, 4, false).is_err());
        // Unknown format, reserved bytes, swizzle past the stored channels, unknown swizzle.
        let mut bad = ok.clone();
        bad[0] = 9;
        assert!(decode_texture(2, &bad, 8, 2, 4, false).is_err());
        let mut bad = ok.clone();
        bad[12] = 1;
        assert!(decode_texture(2, &bad, 8, 2, 4, false).is_err());
        let mut bad = ok.clone();
        bad[4] = Swizzle::B as u8;
        assert!(decode_texture(2, &bad, 8, 2, 4, false).is_err());
        let mut bad = ok.clone();
        bad[5] = 6;
        assert!(decode_texture(2, &bad, 8, 2, 4, false).is_err());
        // BC5 has no sRGB form.
        assert!(decode_texture(2, &ok, 8, 2, 4, true).is_err());
        // Version 1 is bare RGBA8.
        assert_eq!(
            decode_texture(1, &[0u8; 4 * (16 + 4 + 2 + 1)], 8, 2, 4, true).unwrap().format,
            PixelFormat::Rgba8
        );
        assert!(decode_texture(3, &ok, 8, 2, 4, false).is_err());
    }
}
