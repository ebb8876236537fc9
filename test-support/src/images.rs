//! Image files the tests read and write, by code apart from the player's, and the arithmetic
//! they compare images with.

use std::path::Path;

/// An EXR's RGB as `f32`s, row 0 at the top, read by the `image` crate (not by the player's
/// reader).
pub fn read_exr(path: &Path) -> Vec<f32> {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).into_rgb32f().into_raw()
}

/// Writes linear RGB (row 0 at the top) as a NumPy float32 array of shape (height, width, 3).
pub fn write_npy(path: &Path, w: u32, h: u32, rgb: &[f32]) {
    assert_eq!(rgb.len(), (w * h * 3) as usize);
    let data: Vec<u8> = rgb.iter().flat_map(|v| v.to_le_bytes()).collect();
    write_npy_array(path, "<f4", (h, w, 3), &data);
}

/// Writes RGBA8 texels (row 0 at the top) as a NumPy uint8 array of shape (height, width, 4).
pub fn write_npy_rgba8(path: &Path, w: u32, h: u32, rgba: &[u8]) {
    assert_eq!(rgba.len(), (w * h * 4) as usize);
    write_npy_array(path, "|u1", (h, w, 4), rgba);
}

/// A NumPy array file (format 1.0) of element type `descr` and shape `(h, w, c)` holding `data`.
fn write_npy_array(path: &Path, descr: &str, (h, w, c): (u32, u32, u32), data: &[u8]) {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': ({h}, {w}, {c}), }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    bytes.extend(data);
    std::fs::write(path, bytes).unwrap();
}

/// Reads a NumPy float32 array of shape (`h`, `w`, 3), as [`write_npy`] and the tests' Python
/// scripts write them; fails on any other.
pub fn read_npy(path: &Path, w: u32, h: u32) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = String::from_utf8_lossy(&bytes[10..10 + len]);
    assert!(header.contains("'<f4'") && header.contains(&format!("({h}, {w}, 3)")), "{header}");
    bytes[10 + len..].chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
}

/// The mean squared difference of two images' values, summed in `f64`.
pub fn mse(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    a.iter().zip(b).map(|(p, q)| ((p - q) as f64).powi(2)).sum::<f64>() / a.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_files_read_back_and_their_header_is_padded_to_64_bytes() {
        let dir = crate::temp_dir();
        let path = dir.path().join("a.npy");
        let rgb: Vec<f32> = (0..5 * 3 * 3).map(|i| i as f32 * 0.25 - 2.0).collect();
        write_npy(&path, 5, 3, &rgb);
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!((bytes.len() - rgb.len() * 4) % 64, 0);
        assert_eq!(read_npy(&path, 5, 3), rgb);
    }

    #[test]
    fn mse_of_a_constant_offset_is_its_square() {
        let a = [0.5f32, 1.0, 2.0, -1.0];
        let b = a.map(|v| v + 0.5);
        assert_eq!(mse(&a, &b), 0.25);
        assert_eq!(mse(&a, &a), 0.0);
    }
}
