//! Where an image differs from its reference: `kiln-bench --diff REFERENCE.exr IMAGE.exr`
//! prints the figures kiln-bench measures (mean HDR-FLIP, relMSE, RMSE), and both it and
//! `--keep-images` write the per-pixel HDR-FLIP as a heat-map PNG, so that a frame's error can
//! be traced to the surfaces that make it.

use std::path::Path;

use crate::error::{Exit, PlayError, PlayResult};
use crate::image_out::{read_exr, write_png};

/// One pixel of the heat map: 0 black, through red (1/3) and yellow (2/3), to white at 1.
/// A plain ramp rather than FLIP's magma: monotone in brightness, so a grey print reads too.
pub fn heat(value: f32) -> [u8; 4] {
    let v = if value.is_finite() { value.clamp(0.0, 1.0) } else { 1.0 };
    let channel = |start: f32| (((v - start) * 3.0).clamp(0.0, 1.0) * 255.0).round() as u8;
    [channel(0.0), channel(1.0 / 3.0), channel(2.0 / 3.0), 255]
}

/// Writes a per-pixel error map (row-major, values in `[0, 1]`) as a heat-map PNG.
pub fn write_map(path: &Path, width: u32, height: u32, map: &[f32]) -> PlayResult {
    let rgba: Vec<u8> = map.iter().flat_map(|&v| heat(v)).collect();
    write_png(path, width, height, &rgba)
}

/// `--diff`: compares two EXR files, prints the figures and writes the heat map to `map` (a PNG).
pub fn run(reference: &Path, image: &Path, map: &Path) -> PlayResult {
    let (rw, rh, r) = read_exr(reference)?;
    let (w, h, i) = read_exr(image)?;
    if (rw, rh) != (w, h) {
        return Err(PlayError::new(
            Exit::Usage,
            format!(
                "{} is {rw}x{rh} but {} is {w}x{h}: compare images of one size",
                reference.display(),
                image.display()
            ),
        ));
    }
    let (errors, flip_map) = kiln_metrics::compare_with_map(
        super::rgb_image(w, h, &r),
        super::rgb_image(w, h, &i),
    )
    .map_err(|e| {
        PlayError::new(Exit::BadInput, format!("{} against {}: {e}", image.display(), reference.display()))
    })?;
    println!("hdr-flip {:.4}  relmse {:.5}  rmse {:.5}  ({w}x{h})", errors.flip, errors.rel_mse, errors.rmse);
    write_map(map, w, h, &flip_map)?;
    println!("wrote the per-pixel HDR-FLIP to {}", map.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::heat;

    #[test]
    fn the_ramp_runs_black_red_yellow_white() {
        assert_eq!(heat(0.0), [0, 0, 0, 255]);
        assert_eq!(heat(1.0 / 3.0), [255, 0, 0, 255]);
        assert_eq!(heat(2.0 / 3.0), [255, 255, 0, 255]);
        assert_eq!(heat(1.0), [255, 255, 255, 255]);
        assert_eq!(heat(f32::NAN), [255, 255, 255, 255]);
        assert_eq!(heat(-1.0), [0, 0, 0, 255]);
    }
}
