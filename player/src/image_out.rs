//! Writing frames: PNG (tone-mapped sRGB, 8 bits) or OpenEXR (linear scene radiance, 32-bit
//! float RGB). Files are written to a temporary name and renamed, so a reader never sees half.

use std::io::Cursor;

use image::ExtendedColorType;
use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use std::path::Path;

use crate::error::{Exit, PlayError, PlayResult};

/// Output image types, by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// `.png`: tone-mapped sRGB.
    Png,
    /// `.exr`: linear radiance before exposure and tone mapping.
    Exr,
}

impl OutputKind {
    /// The kind for `path`'s extension, or a usage error.
    pub fn of(path: &Path) -> PlayResult<OutputKind> {
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("png") => Ok(OutputKind::Png),
            Some("exr") => Ok(OutputKind::Exr),
            _ => Err(PlayError::new(
                Exit::Usage,
                format!(
                    "{}: the output must end in .png (tone-mapped) or .exr (linear radiance)",
                    path.display()
                ),
            )),
        }
    }
}

/// Writes `bytes` to a temporary file beside `path` and renames it into place.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> PlayResult {
    let io = |e: std::io::Error| PlayError::new(Exit::Io, format!("{}: {e}", path.display()));
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    std::fs::write(&tmp, bytes).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}

/// Writes RGBA8 pixels (alpha ignored) as an RGB PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> PlayResult {
    let rgb: Vec<u8> = rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
    if rgb.len() as u64 != width as u64 * height as u64 * 3 {
        return Err(PlayError::new(Exit::Gpu, "readback size mismatch"));
    }
    let mut out = Vec::new();
    // Fast compression: the output is written on the first frame's critical path.
    let encoder = PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive);
    encoder
        .write_image(&rgb, width, height, ExtendedColorType::Rgb8)
        .map_err(|e| PlayError::new(Exit::Io, format!("encoding PNG: {e}")))?;
    write_atomic(path, &out)
}

/// Writes RGBA32F pixels (alpha ignored) as a float RGB OpenEXR file. The blocks are
/// compressed and written one after another, in increasing line order: the same pixels always
/// give the same bytes (the `image` crate's encoder compresses blocks on several threads and
/// writes them in the order they finish).
pub fn write_exr(path: &Path, width: u32, height: u32, rgba: &[f32]) -> PlayResult {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let (w, h) = (width as usize, height as usize);
    if rgba.len() != w * h * 4 {
        return Err(PlayError::new(Exit::Gpu, "readback size mismatch"));
    }
    let pixels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let i = (p.y() * w + p.x()) * 4;
        (rgba[i], rgba[i + 1], rgba[i + 2])
    });
    let mut out = Cursor::new(Vec::new());
    Image::from_channels((w, h), pixels)
        .write()
        .non_parallel()
        .to_buffered(&mut out)
        .map_err(|e| PlayError::new(Exit::Io, format!("encoding EXR: {e}")))?;
    write_atomic(path, &out.into_inner())
}

/// Reads an EXR written by [`write_exr`] back as (width, height, RGB f32).
pub fn read_exr(path: &Path) -> PlayResult<(u32, u32, Vec<f32>)> {
    let img = image::open(path)
        .map_err(|e| PlayError::new(Exit::Io, format!("{}: {e}", path.display())))?
        .into_rgb32f();
    Ok((img.width(), img.height(), img.into_raw()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same pixels give the same file, byte for byte, however many blocks it has (format
    /// round-trip tests and bit-identical comparisons rely on it).
    #[test]
    fn exr_bytes_depend_only_on_the_pixels() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (96u32, 200u32);
        let mut x = 0x9e37_79b9_u32;
        let px: Vec<f32> = (0..w * h * 4)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                (x % 1000) as f32 / 250.0
            })
            .collect();
        let first = dir.path().join("0.exr");
        write_exr(&first, w, h, &px).unwrap();
        let expected = std::fs::read(&first).unwrap();
        for k in 1..8 {
            let path = dir.path().join(format!("{k}.exr"));
            write_exr(&path, w, h, &px).unwrap();
            assert!(std::fs::read(&path).unwrap() == expected, "write {k} differs");
        }
        let (rw, rh, rgb) = read_exr(&first).unwrap();
        assert_eq!((rw, rh), (w, h));
        assert!(rgb.iter().zip(px.chunks_exact(4).flat_map(|p| &p[..3])).all(|(a, b)| a == b));
    }

    #[test]
    fn exr_round_trips_linear_values_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.exr");
        let px = [0.5f32, 2.0, 1e-3, 1.0, 100.0, 0.0, 0.25, 1.0];
        write_exr(&path, 2, 1, &px).unwrap();
        let (w, h, rgb) = read_exr(&path).unwrap();
        assert_eq!((w, h), (2, 1));
        assert_eq!(rgb, vec![0.5, 2.0, 1e-3, 100.0, 0.0, 0.25]);
    }

    #[test]
    fn output_kind_follows_the_extension() {
        assert_eq!(OutputKind::of(Path::new("a.PNG")).unwrap(), OutputKind::Png);
        assert_eq!(OutputKind::of(Path::new("a.exr")).unwrap(), OutputKind::Exr);
        assert_eq!(OutputKind::of(Path::new("a.jpg")).unwrap_err().exit, Exit::Usage);
    }
}
