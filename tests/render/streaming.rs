//! Texture streaming (`TextureUpload::CoarseFirst`): the first frame samples each texture's
//! levels from the first at most 256 texels on a side, the finer levels upload after it and the
//! frames switch to the full chains. The first frame must really show the coarse levels, the
//! refined frames (and every written or measured one) must equal a whole load bit for bit, the
//! load breakdown must count the two parts' bytes, and the validation layer must stay clean
//! through the refinement, a resize after it, and a close before it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use kiln_compiler::ir::{Texture, TextureRole};
use kiln_compiler::settings::{Settings, TextureFormat};
use kiln_format::manifest::{LightKind, Wrap};
use kiln_format::sections::{self, PixelFormat};
use kiln_format::{Checksums, KilnFile, SceneView};
use kiln_player::bench;
use kiln_player::render::Readable;
use kiln_player::session::Session;
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{H, Pinhole, W, WrittenExr, fast_settings, light, square, traced, written_exr};

/// The checker's size: over 256 texels on both sides, so that levels 0 and 1 (516 × 260 and
/// 258 × 130) come after the first frame and level 2 (129 × 65) is the first one before it.
/// Neither is a multiple of the 4 × 4 block: BC levels end in partial blocks on both sides of
/// the split.
const TEX_W: u32 = 516;
const TEX_H: u32 = 260;

/// A floor under a two-colour checker of one-texel cells, seen from straight above, each texel
/// about four pixels wide (sampled from mip 0, nearest). Its mip 1 averages every cell with its
/// neighbours: the coarse levels are a flat grey where mip 0 alternates light and dark.
fn checker_floor(format: TextureFormat) -> Vec<u8> {
    let mut scene = scene_of(&square(0.0, 10.0));
    // Two texels per scene unit: the 96 × 72 image spans about 9 units, ~4 pixels per texel.
    let per_unit = 2.0;
    scene.uvs = scene
        .vertices
        .iter()
        .map(|v| [v.position[0] * per_unit / TEX_W as f32, v.position[2] * per_unit / TEX_H as f32])
        .collect();
    let rgba = (0..TEX_H)
        .flat_map(|y| (0..TEX_W).map(move |x| (x, y)))
        .flat_map(|(x, y)| if (x + y) % 2 == 0 { [235, 235, 235, 255] } else { [25, 25, 25, 255] })
        .collect();
    scene.textures = vec![Texture {
        name: "checker".into(),
        width: TEX_W,
        height: TEX_H,
        rgba,
        role: TextureRole::Color,
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        mag_linear: false,
    }];
    let m = &mut scene.materials[0].gpu;
    m.base_color_texture = 0;
    m.flags &= !sections::MaterialFlags::DIFFUSE_ONLY;
    scene.lights.push(light(LightKind::Point, [1.0, 5.0, 1.0], [0.0, -1.0, 0.0], 40.0));
    scene
        .cameras
        .push(Pinhole::new([0.0, 8.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 60.0, W, H).file_camera());
    compile(scene, Settings { texture_format: format, ..fast_settings() })
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let file = dir.join(format!("{name}.kiln"));
    std::fs::write(&file, bytes).unwrap();
    file
}

/// Bytes of each level of a `w` × `h` texture down to 1 × 1, finest first, computed here from the
/// format's rules (RGBA8: 4 bytes a texel; BC7: 16 bytes a 4 × 4 block, partial blocks whole).
fn level_bytes(w: u32, h: u32, format: PixelFormat) -> Vec<u64> {
    let (mut w, mut h, mut out) = (w, h, Vec::new());
    loop {
        out.push(match format {
            PixelFormat::Rgba8 => w as u64 * h as u64 * 4,
            _ => w.div_ceil(4) as u64 * h.div_ceil(4) as u64 * 16,
        });
        if w == 1 && h == 1 {
            return out;
        }
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
}

/// The texture's format and mip count as the file stores them.
fn stored(bytes: &[u8]) -> (PixelFormat, u32) {
    let f = KilnFile::from_bytes(bytes, Checksums::Eager).unwrap();
    let v = SceneView::new(&f).unwrap();
    (v.texture(0).unwrap().format, v.manifest.textures[0].mip_levels)
}

/// Mean absolute difference of horizontally adjacent pixels' luminance over the mean
/// luminance: ~0.5 where the checker's cells show, near 0 on a flat grey under a smooth light.
fn edge_contrast(rgb: &[f32]) -> f64 {
    let lum: Vec<f64> = rgb.chunks_exact(3).map(|p| (p[0] + p[1] + p[2]) as f64 / 3.0).collect();
    let (mut diff, mut n) = (0.0, 0usize);
    for row in lum.chunks_exact(W as usize) {
        for x in 0..row.len() - 1 {
            diff += (row[x + 1] - row[x]).abs();
            n += 1;
        }
    }
    let mean = lum.iter().sum::<f64>() / lum.len() as f64;
    assert!(mean > 1e-3, "the floor is black");
    diff / n as f64 / mean
}

/// The radiance of the frame [`Session::frame`] just read back, RGB.
fn radiance(session: &mut Session) -> Vec<f32> {
    let bytes = session.readback.as_mut().and_then(|r| r.buffer.mapped()).unwrap();
    let rgba: &[f32] = bytemuck::cast_slice(&bytes[..(W * H * 16) as usize]);
    rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
}

#[test]
fn headless_output_with_streamed_textures_is_bit_identical_to_a_whole_load() {
    let dir = gpu_test!();
    for (format, name) in [(TextureFormat::Rgba8, "rgba8"), (TextureFormat::Bc, "bc")] {
        let file = write(dir.path(), name, &checker_floor(format));
        // Two frames: the second reads the first's history, which the refinement must restart.
        let WrittenExr { bytes: streamed, times, .. } =
            written_exr(dir.path(), &format!("{name}-streamed"), Options::new(&file, W, H).streaming(), 2);
        let WrittenExr { bytes: whole, times: whole_times, .. } =
            written_exr(dir.path(), &format!("{name}-whole"), Options::new(&file, W, H), 2);
        assert!(streamed == whole, "{name}: the streamed output differs from the whole load's");
        // The comparison saw a streamed load: its first frame did not wait for levels 0 and 1.
        assert_eq!(times.after_first_frame, ["texture#0 mips 0-1"], "{name}");
        assert!(times.textures_refined_since_start_ms > times.first_frame_since_start_ms, "{name}");
        assert!(whole_times.after_first_frame.is_empty(), "{name}: {:?}", whole_times.after_first_frame);
    }
}

#[test]
fn behind_a_fallback_streamed_textures_still_give_the_chosen_techniques_output() {
    let dir = gpu_test!();
    let file = write(dir.path(), "rt", &checker_floor(TextureFormat::Rgba8));
    let WrittenExr { bytes: both, times, .. } =
        written_exr(dir.path(), "both", traced(Options::new(&file, W, H)).progressive().streaming(), 2);
    let complete = written_exr(dir.path(), "complete", traced(Options::new(&file, W, H)), 2).bytes;
    assert!(both == complete, "behind a fallback with streamed textures the output differs");
    // The texture's finer levels and its texels for the ray-traced passes came after the
    // fallback's first frame, with the sections only those passes read.
    assert_eq!(times.fallback_frames, 1);
    assert!(
        times.after_first_frame.contains(&"texture#0 mips 0-1".to_string()),
        "{:?}",
        times.after_first_frame
    );
    assert!(times.after_first_frame.contains(&"bvh".to_string()), "{:?}", times.after_first_frame);
}

#[test]
fn the_first_frame_samples_the_coarse_levels_and_the_next_the_full_chain() {
    let dir = gpu_test!();
    let file = write(dir.path(), "checker", &checker_floor(TextureFormat::Rgba8));
    let open = |o: Options| {
        let mut o = o.build();
        o.readback = Some(Readable::Radiance);
        Session::open(&o, Instant::now()).unwrap()
    };
    let mut streamed = open(Options::new(&file, W, H).streaming());
    streamed.frame(true).unwrap();
    let coarse = radiance(&mut streamed);
    streamed.frame(true).unwrap();
    let refined = radiance(&mut streamed);
    let mut whole = open(Options::new(&file, W, H));
    whole.frame(true).unwrap();
    let full = radiance(&mut whole);
    assert_eq!(whole.close(), 0, "validation errors (whole load)");
    let (c, r) = (edge_contrast(&coarse), edge_contrast(&refined));
    eprintln!("checker floor: edge contrast {c:.3} in the first (coarse) frame, {r:.3} refined");
    // Mip 0's cells show once refined; the first frame, from mip 1 down, is a flat grey.
    assert!(r > 0.2, "the refined frame does not show the checker's cells: {r}");
    assert!(c < 0.05 && c * 10.0 < r, "the first frame shows mip 0: contrast {c} against {r} refined");
    assert!(refined == full, "the refined frame differs from a whole load's first frame");
    // A resize after the refinement rebinds the full views.
    streamed.resize(W / 2, H / 2).unwrap();
    streamed.frame(false).unwrap();
    assert_eq!(streamed.close(), 0, "validation errors through the refinement and a resize");

    // Closed before the refinement: no frame at all, and a coarse frame still in flight (its
    // finer levels never uploaded) release everything cleanly.
    let never = open(Options::new(&file, W, H).streaming());
    assert_eq!(never.close(), 0, "validation errors closing before the first frame");
    let mut in_flight = open(Options::new(&file, W, H).streaming());
    in_flight.record_and_submit(|_, _| {}, &[], &[]).unwrap();
    assert_eq!(in_flight.close(), 0, "validation errors closing with a coarse frame in flight");
}

#[test]
fn bench_counts_the_coarse_and_fine_texture_bytes_and_times_the_refinement() {
    let dir = gpu_test!();
    for (format, name) in [(TextureFormat::Rgba8, "rgba8"), (TextureFormat::Bc, "bc")] {
        let bytes = checker_floor(format);
        let (pixel, mips) = stored(&bytes);
        let levels = level_bytes(TEX_W, TEX_H, pixel);
        assert_eq!(mips as usize, levels.len(), "{name}: the compiler wrote a full chain");
        // Levels 0 and 1 are over 256 texels wide; level 2 (129 × 65) is the first coarse one.
        let (fine, coarse): (u64, u64) = (levels[..2].iter().sum(), levels[2..].iter().sum());
        let file = write(dir.path(), name, &bytes);
        let report =
            bench::run(&Options::new(&file, 48, 32).streaming().build(), 1, 2, Instant::now()).unwrap();
        assert_eq!(report.validation_errors, 0, "{name}");
        let json = serde_json::to_value(&report).unwrap();
        let load = &json["load"];
        let later: Vec<&str> =
            load["after_first_frame"].as_array().unwrap().iter().map(|s| s.as_str().unwrap()).collect();
        assert_eq!(later, ["texture#0 mips 0-1"], "{name}");
        assert_eq!(load["coarse_texture_bytes"].as_u64(), Some(coarse), "{name}: {load}");
        assert_eq!(load["refined_texture_bytes"].as_u64(), Some(fine), "{name}: {load}");
        let ms = |k: &str| load[k].as_f64().unwrap_or_else(|| panic!("{k} missing from {load}"));
        assert!(ms("textures_refined_since_start_ms") > ms("first_frame_since_start_ms"), "{name}: {load}");
        assert!(ms("resident_since_start_ms") > ms("first_frame_since_start_ms"), "{name}: {load}");
        assert!(ms("rest_upload_ms") > 0.0, "{name}");
        // The section table says the same.
        let fates = json["sections"].as_array().unwrap();
        let texture = fates.iter().find(|s| s["section"] == "texture#0").unwrap();
        assert_eq!(texture["fine_mips"], serde_json::json!([0, 1]), "{name}");
        assert_eq!(texture["after_first_frame"], true, "{name}");

        // Without streaming every level comes before the first frame.
        let whole = bench::run(&Options::new(&file, 48, 32).build(), 1, 2, Instant::now()).unwrap();
        let load = serde_json::to_value(&whole).unwrap()["load"].clone();
        assert_eq!(load["coarse_texture_bytes"].as_u64(), Some(coarse + fine), "{name}: {load}");
        assert_eq!(load["refined_texture_bytes"].as_u64(), Some(0), "{name}: {load}");
        assert_eq!(load["after_first_frame"].as_array().map(Vec::len), Some(0), "{name}: {load}");
        assert!(
            load["textures_refined_since_start_ms"].as_f64().unwrap()
                < load["first_frame_since_start_ms"].as_f64().unwrap(),
            "{name}: {load}"
        );
    }
}
