//! `kiln export`: image-like sections as files a user can look at. Float data goes to PFM
//! (little-endian Portable Float Map) or OpenEXR, 8- and 16-bit data to PNG; the extension of
//! the output path decides.

use std::path::Path;

use kiln_format::manifest::ShadowProjection;
use kiln_format::sections::Swizzle;
use kiln_format::{Checksums, KilnFile, SceneView, sections};

use crate::cli::ExportArgs;
use crate::exit::{CliError, CliResult, Exit, format_error};

/// An image: width, height, channels (1, 3 or 4), values row by row from the top.
struct Image {
    width: u32,
    height: u32,
    channels: u32,
    data: Vec<f32>,
    /// For PNG: the maximum value mapped to white (values are scaled by 1 / scale).
    scale: f32,
    /// For PNG: 16 bits per channel instead of 8.
    wide: bool,
}

/// Section names `export` accepts.
pub const EXPORTABLE: &[&str] = &[
    "brdf-lut",
    "shadow-map",
    "texture",
    "media-visibility",
    "probe-irradiance",
    "probe-visibility",
    "environment-map",
    "environment-filtered",
];

/// Runs `kiln export`.
pub fn run(args: &ExportArgs) -> CliResult {
    let (name, index) = match args.section.split_once(':') {
        Some((n, i)) => (
            n,
            i.parse::<u32>().map_err(|_| CliError::usage(format!("section index '{i}' is not a number")))?,
        ),
        None => (args.section.as_str(), 0),
    };
    if !EXPORTABLE.contains(&name) {
        return Err(CliError::usage(format!(
            "cannot export '{name}': exportable sections are {}",
            EXPORTABLE.join(", ")
        )));
    }
    crate::clobber::refuse(&[("-o", &args.output)], std::slice::from_ref(&args.file))?;
    let file = KilnFile::open(&args.file, Checksums::OnAccess).map_err(|e| format_error(&args.file, e))?;
    let view = SceneView::new(&file).map_err(|e| format_error(&args.file, e))?;
    let missing = || {
        CliError::input(format!(
            "{}: has no {name}:{index} section (kiln inspect lists them)",
            args.file.display()
        ))
    };
    let image = match name {
        "brdf-lut" => {
            let info = view.manifest.brdf_lut.ok_or_else(missing)?;
            let lut: &[[u16; 2]] = file
                .pod(sections::BRDF_LUT, 0)
                .map_err(|e| format_error(&args.file, e))?
                .ok_or_else(missing)?;
            let n = info.resolution;
            // Row j is roughness: the top row of the image is the smoothest.
            let data = lut.iter().flat_map(|t| [t[0] as f32 / 65535.0, t[1] as f32 / 65535.0, 0.0]).collect();
            Image { width: n, height: n, channels: 3, data, scale: 1.0, wide: true }
        }
        "shadow-map" => {
            let info = view.manifest.shadow_maps.get(index as usize).ok_or_else(missing)?;
            let depths: &[f32] = file
                .pod(sections::SHADOW_MAP, index)
                .map_err(|e| format_error(&args.file, e))?
                .ok_or_else(missing)?;
            let faces = if info.projection == ShadowProjection::Cube { 6 } else { 1 };
            // Faces are stacked from the top in the file's order; texels without an occluder
            // stay f32::MAX in float files and white in PNG.
            Image {
                width: info.resolution,
                height: info.resolution * faces,
                channels: 1,
                data: depths.to_vec(),
                scale: info.far,
                wide: true,
            }
        }
        "texture" => {
            let info = view.manifest.textures.get(index as usize).ok_or_else(missing)?;
            let texels = view.texture(index as usize).map_err(|e| format_error(&args.file, e))?;
            // Mip 0 as stored (block-compressed textures decoded), swizzled as a renderer samples it.
            let level = texels.level_slices(info.width, info.height, info.mip_levels)[0];
            let stored = crate::bake::bc::decode_level(texels.format, level, info.width, info.height);
            let data = stored
                .chunks_exact(4)
                .flat_map(|p| {
                    texels.swizzle.map(|s| match s {
                        Swizzle::Zero => 0.0,
                        Swizzle::One => 1.0,
                        c => p[c as usize] as f32 / 255.0,
                    })
                })
                .collect();
            Image { width: info.width, height: info.height, channels: 4, data, scale: 1.0, wide: false }
        }
        "probe-irradiance" | "probe-visibility" => {
            // Index = the z slice: its probes' tiles as the atlas lays them out (borders
            // included), irradiance as RGB (index dims.z + z: the emitted layer), distance
            // moments as mean and mean square.
            let v = kiln_format::probes::ProbeVolume::read(&file)
                .map_err(|e| format_error(&args.file, e))?
                .ok_or_else(missing)?;
            let h = v.header;
            let [w, ht, layers] =
                if name == "probe-irradiance" { h.irradiance_extent() } else { h.visibility_extent() };
            if index >= layers {
                return Err(missing());
            }
            let texels = (w * ht) as usize;
            let at = index as usize * texels;
            let data = if name == "probe-irradiance" {
                v.irradiance[at..at + texels]
                    .iter()
                    .flat_map(|&t| kiln_format::probes::decode_rgb9e5(t))
                    .collect()
            } else {
                v.visibility[at..at + texels]
                    .iter()
                    .flat_map(|t| {
                        [half::f16::from_bits(t[0]).to_f32(), half::f16::from_bits(t[1]).to_f32(), 0.0]
                    })
                    .collect()
            };
            let scale = if name == "probe-irradiance" { 1.0 } else { h.max_distance * h.max_distance };
            Image { width: w, height: ht, channels: 3, data, scale, wide: true }
        }
        "environment-map" | "environment-filtered" => {
            // The radiance map (index 0), or prefiltered level `index` (roughness index / (levels
            // − 1)), as linear RGB, row 0 the zenith.
            let e = kiln_format::environment::Environment::read(&file)
                .map_err(|e| format_error(&args.file, e))?
                .ok_or_else(missing)?;
            let h = e.header;
            let (w, ht, texels) = if name == "environment-map" {
                if index != 0 {
                    return Err(missing());
                }
                (h.map[0], h.map[1], e.map)
            } else {
                if index >= h.filtered[2] {
                    return Err(missing());
                }
                let [w, ht] = h.filtered_extent(index);
                let at = h.filtered_offset(index);
                (w, ht, &e.filtered[at..at + (w * ht) as usize])
            };
            let data = texels.iter().flat_map(|&t| kiln_format::probes::decode_rgb9e5(t)).collect();
            Image { width: w, height: ht, channels: 3, data, scale: 1.0, wide: true }
        }
        _ => {
            let info = view.manifest.media_visibility.as_ref().ok_or_else(missing)?;
            let cells: &[u8] = file
                .pod(sections::MEDIA_VISIBILITY, index)
                .map_err(|e| format_error(&args.file, e))?
                .ok_or_else(missing)?;
            // z slices stacked from the top, each dims.x wide and dims.y tall.
            let data = cells.iter().map(|&b| b as f32 / 255.0).collect();
            Image {
                width: info.dims[0],
                height: info.dims[1] * info.dims[2],
                channels: 1,
                data,
                scale: 1.0,
                wide: false,
            }
        }
    };
    write(&image, &args.output)?;
    if !args.quiet {
        println!(
            "wrote {} ({}x{}, {} channel(s)) from {name}:{index}",
            args.output.display(),
            image.width,
            image.height,
            image.channels
        );
    }
    Ok(())
}

fn write(img: &Image, path: &Path) -> CliResult {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    let io = |e: std::io::Error| CliError::io(format!("{}: {e}", path.display()));
    match ext.as_str() {
        "pfm" => {
            // PFM holds 1 or 3 channels, rows from the bottom; a negative scale means little-endian.
            let ch = if img.channels == 1 { 1 } else { 3 };
            let mut out =
                format!("{}\n{} {}\n-1.0\n", if ch == 1 { "Pf" } else { "PF" }, img.width, img.height)
                    .into_bytes();
            for y in (0..img.height).rev() {
                for x in 0..img.width {
                    let o = ((y * img.width + x) * img.channels) as usize;
                    for c in 0..ch {
                        out.extend_from_slice(&img.data[o + c as usize].to_le_bytes());
                    }
                }
            }
            std::fs::write(path, out).map_err(io)
        }
        "exr" => {
            let rgba: Vec<f32> = (0..(img.width * img.height) as usize)
                .flat_map(|i| {
                    let p = &img.data[i * img.channels as usize..(i + 1) * img.channels as usize];
                    match img.channels {
                        1 => [p[0], p[0], p[0], 1.0],
                        3 => [p[0], p[1], p[2], 1.0],
                        _ => [p[0], p[1], p[2], p[3]],
                    }
                })
                .collect();
            let buf = image::Rgba32FImage::from_raw(img.width, img.height, rgba)
                .ok_or_else(|| CliError::new(Exit::BadInput, "image size mismatch"))?;
            buf.save(path).map_err(|e| CliError::io(format!("{}: {e}", path.display())))
        }
        "png" => {
            let scale = img.scale.max(f32::MIN_POSITIVE);
            let norm = |v: f32| (v / scale).clamp(0.0, 1.0);
            let color = match img.channels {
                1 => {
                    if img.wide {
                        image::ColorType::L16
                    } else {
                        image::ColorType::L8
                    }
                }
                3 => {
                    if img.wide {
                        image::ColorType::Rgb16
                    } else {
                        image::ColorType::Rgb8
                    }
                }
                _ => {
                    if img.wide {
                        image::ColorType::Rgba16
                    } else {
                        image::ColorType::Rgba8
                    }
                }
            };
            let bytes: Vec<u8> = if img.wide {
                img.data.iter().flat_map(|&v| ((norm(v) * 65535.0).round() as u16).to_ne_bytes()).collect()
            } else {
                img.data.iter().map(|&v| (norm(v) * 255.0).round() as u8).collect()
            };
            image::save_buffer(path, &bytes, img.width, img.height, color)
                .map_err(|e| CliError::io(format!("{}: {e}", path.display())))
        }
        _ => Err(CliError::usage(format!("{}: unknown image type; use .pfm, .exr or .png", path.display()))),
    }
}
