//! Writing a sweep: `results.json`, `results.csv`, one chart per effect and camera (SVG and
//! PNG), `index.html`, and the table on the terminal.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use kiln_plot::{Chart, ChartPoint, Page, Section, Table};

use crate::error::{Exit, PlayError, PlayResult};
use crate::image_out::write_atomic;
use crate::reference::write_exr;

use super::plan::{describe_fixed_map, transport};
use super::results::{Point, Results};

/// Width and height of the PNG charts.
pub const PNG_SIZE: (u32, u32) = (1000, 700);

/// A file name made of `parts`: letters, digits, `.`, `-`, `_` kept, anything else `_`.
pub fn file_name(parts: &[&str], extension: &str) -> String {
    let joined = parts.join("-");
    let clean: String = joined
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_') { c } else { '_' })
        .collect();
    format!("{clean}.{extension}")
}

/// Writes a measured image (linear RGB, EXR with the frame or sample count in the header) to
/// `OUT/images/` for independent checking.
pub fn keep_image(
    out: &Path,
    camera: &str,
    what: &str,
    width: u32,
    height: u32,
    rgb: &[f32],
    count: u32,
) -> PlayResult {
    write_exr(&kept(out, &[&camera_label(camera), what], "exr")?, width, height, rgb, count)
}

/// Writes the per-pixel HDR-FLIP of a measured image beside it, as `...-flip.png` (a heat map:
/// black no error, red, yellow, white the largest).
pub fn keep_error_map(
    out: &Path,
    camera: &str,
    what: &str,
    width: u32,
    height: u32,
    map: &[f32],
) -> PlayResult {
    super::diff::write_map(&kept(out, &[&camera_label(camera), what, "flip"], "png")?, width, height, map)
}

/// The path of a kept file named by `parts` in `OUT/images/`, the folder made.
fn kept(out: &Path, parts: &[&str], extension: &str) -> PlayResult<PathBuf> {
    let dir = out.join("images");
    create_dir(&dir)?;
    Ok(dir.join(file_name(parts, extension)))
}

fn camera_label(camera: &str) -> String {
    if camera == "file" { "file".to_string() } else { format!("cam{:08x}", short_hash(camera)) }
}

fn short_hash(s: &str) -> u32 {
    xxhash_rust::xxh3::xxh3_64(s.as_bytes()) as u32
}

/// Creates a folder and its parents, or says which could not be.
pub fn create_dir(dir: &Path) -> PlayResult {
    std::fs::create_dir_all(dir)
        .map_err(|e| PlayError::new(Exit::Io, format!("{}: cannot create the folder: {e}", dir.display())))
}

/// What charts and tables call the scene: the `.kiln` file's name without its extension
/// (manifest names are often just "scene"), and the manifest's name when it says more.
pub fn scene_label(results: &Results) -> String {
    let stem = Path::new(&results.scene.file).file_stem().map(|s| s.to_string_lossy().into_owned());
    match stem {
        Some(stem)
            if stem != results.scene.name
                && results.scene.name != "scene"
                && !results.scene.name.is_empty() =>
        {
            format!("{stem} ({})", results.scene.name)
        }
        Some(stem) => stem,
        None => results.scene.name.clone(),
    }
}

/// The charts of a sweep: one per (effect, camera), in sweep order.
pub fn charts(results: &Results) -> Vec<(String, String, Chart)> {
    let mut groups: Vec<((String, String), Vec<&Point>)> = Vec::new();
    for p in &results.points {
        let key = (p.effect.clone(), p.camera.clone());
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(p),
            None => groups.push((key, vec![p])),
        }
    }
    let cameras = results.references.len();
    groups
        .into_iter()
        .map(|((effect, camera), points)| {
            let bounces = points.first().map_or(0, |p| p.reference_bounces);
            let reference = results.references.iter().find(|r| r.camera == camera && r.bounces == bounces);
            let floor = reference.map(|r| r.noise_floor.flip);
            let spp = reference.map_or(0, |r| r.spp);
            let mut subtitle = vec![
                format!(
                    "{} at {}x{} on {} (driver {}), camera {camera}",
                    scene_label(results),
                    results.width,
                    results.height,
                    results.device.name,
                    results.device.driver_version
                ),
                format!("reference: path traced, {}, {spp} spp", transport(bounces)),
            ];
            if effect != "frame" {
                subtitle
                    .push(format!("fixed: {}", describe_fixed_map(chart_fixed(results, &effect), &effect)));
            }
            let chart = Chart {
                title: if cameras > 1 {
                    format!("{effect}: {} (camera {camera})", scene_label(results))
                } else {
                    format!("{effect}: {}", scene_label(results))
                },
                subtitle,
                x_label: "GPU ms to the image (frames accumulated x median ms per frame)".into(),
                y_label: "mean HDR-FLIP against the reference".into(),
                points: points
                    .iter()
                    .map(|p| ChartPoint {
                        label: p.label.clone(),
                        series: p.technique.clone(),
                        x: p.image_ms,
                        y: p.error.flip,
                    })
                    .collect(),
                noise_floor: floor,
            };
            (effect, camera, chart)
        })
        .collect()
}

/// Writes `results.json`, `results.csv`, the charts and `index.html` into `out`; returns the
/// files written.
pub fn write(results: &Results, out: &Path) -> PlayResult<Vec<PathBuf>> {
    create_dir(out)?;
    let mut written = Vec::new();
    let mut put = |name: &str, bytes: &[u8]| -> PlayResult {
        let path = out.join(name);
        write_atomic(&path, bytes)?;
        written.push(path);
        Ok(())
    };
    put("results.json", results.to_json().as_bytes())?;
    put("results.csv", results.to_csv().as_bytes())?;
    let mut sections = Vec::new();
    let mut cameras: Vec<&str> = results.references.iter().map(|r| r.camera.as_str()).collect();
    cameras.dedup();
    let single_camera = cameras.len() <= 1;
    for (effect, camera, chart) in charts(results) {
        let stem =
            if single_camera { effect.clone() } else { format!("{effect}-cam{:08x}", short_hash(&camera)) };
        let svg_file = file_name(&[&stem], "svg");
        let png_file = file_name(&[&stem], "png");
        let svg = kiln_plot::svg(&chart)
            .map_err(|e| PlayError::new(Exit::Io, format!("drawing {stem}.svg: {e}")))?;
        put(&svg_file, svg.as_bytes())?;
        let png = kiln_plot::png(&chart, PNG_SIZE.0, PNG_SIZE.1)
            .map_err(|e| PlayError::new(Exit::Io, format!("drawing {stem}.png: {e}")))?;
        put(&png_file, &png)?;
        let points: Vec<&Point> =
            results.points.iter().filter(|p| p.effect == effect && p.camera == camera).collect();
        sections.push(Section { heading: chart.title.clone(), svg_file, png_file, table: table(&points) });
    }
    let mut notes = vec![
        format!(
            "{} ({}) at {}x{} on {}, driver {} {}, GPU UUID {}",
            scene_label(results),
            results.scene.file,
            results.width,
            results.height,
            results.device.name,
            results.device.driver_name,
            results.device.driver_version,
            results.device.uuid
        ),
        format!(
            "GPU time: median over {} frames after {} warm-up per configuration; sweep took {:.1} s",
            results.timing.frames, results.timing.warmup_frames, results.sweep_seconds
        ),
        format!("errors: {}", results.metrics),
    ];
    for r in &results.references {
        notes.push(format!(
            "reference (camera {}, {}): {} spp{}, noise floor: FLIP {:.4}, relMSE {:.3e}, RMSE {:.3e}",
            r.camera,
            transport(r.bounces),
            r.spp,
            if r.cached { " (cached)" } else { "" },
            r.noise_floor.flip,
            r.noise_floor.rel_mse,
            r.noise_floor.rmse
        ));
    }
    for s in &results.skipped {
        notes.push(format!("skipped {} {}: {}", s.effect, s.technique, s.reason));
    }
    notes.extend(results.warnings.iter().map(|w| format!("warning: {w}")));
    let page = Page { title: format!("kiln-bench: {}", scene_label(results)), notes, sections };
    put("index.html", kiln_plot::index_html(&page).as_bytes())?;
    Ok(written)
}

/// The table of a chart's points: front points highlighted.
fn table(points: &[&Point]) -> Table {
    let headers = [
        "technique",
        "knobs",
        "frames",
        "ms/frame (p10-p90)",
        "effect ms",
        "image ms",
        "FLIP",
        "relMSE",
        "RMSE",
        "note",
    ];
    let rows = points
        .iter()
        .map(|p| {
            vec![
                p.technique.clone(),
                p.knobs.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" "),
                p.frames.to_string(),
                format!("{:.3} ({:.3}-{:.3})", p.frame_ms, p.frame_p10_ms, p.frame_p90_ms),
                format!("{:.3}", p.effect_ms),
                format!("{:.3}", p.image_ms),
                format!("{:.4}", p.error.flip),
                format!("{:.3e}", p.error.rel_mse),
                format!("{:.3e}", p.error.rmse),
                note(p),
            ]
        })
        .collect();
    Table {
        headers: headers.iter().map(|s| s.to_string()).collect(),
        rows,
        highlight: points.iter().map(|p| p.on_front).collect(),
    }
}

fn note(p: &Point) -> String {
    let mut n = Vec::new();
    if p.on_front {
        n.push("front".to_string());
    }
    if p.below_noise_floor {
        n.push("within the reference's noise".to_string());
    }
    if let Some(r) = &p.regression {
        n.push(format!("REGRESSION: {r}"));
    }
    n.join("; ")
}

/// The terminal summary: per chart, its points sorted by time.
pub fn text(results: &Results) -> String {
    let mut s = format!(
        "{} at {}x{} on {} (driver {})\n",
        scene_label(results),
        results.width,
        results.height,
        results.device.name,
        results.device.driver_version
    );
    for r in &results.references {
        s.push_str(&format!(
            "reference, camera {}, {}: {} spp{}; noise floor FLIP {:.4} (relMSE {:.2e}, RMSE {:.2e})\n",
            r.camera,
            transport(r.bounces),
            r.spp,
            if r.cached { " (cached)" } else { &"" },
            r.noise_floor.flip,
            r.noise_floor.rel_mse,
            r.noise_floor.rmse
        ));
    }
    let mut groups: BTreeMap<(String, String), Vec<&Point>> = BTreeMap::new();
    for p in &results.points {
        groups.entry((p.effect.clone(), p.camera.clone())).or_default().push(p);
    }
    for ((effect, camera), mut points) in groups {
        points.sort_by(|a, b| a.image_ms.total_cmp(&b.image_ms));
        let bounces = points.first().map_or(0, |p| p.reference_bounces);
        s.push_str(&format!("\n{effect} (camera {camera}; against {})", transport(bounces)));
        if effect != "frame" {
            s.push_str(&format!("; fixed: {}", describe_fixed_map(chart_fixed(results, &effect), &effect)));
        }
        s.push_str(&format!(
            "\n  {:<28} {:>9} {:>9} {:>10} {:>8} {:>10}  {}\n",
            "point", "ms/frame", "effect ms", "image ms", "FLIP", "relMSE", "note"
        ));
        for p in points {
            s.push_str(&format!(
                "  {:<28} {:>9.3} {:>9.3} {:>10.3} {:>8.4} {:>10.3e}  {}\n",
                p.label,
                p.frame_ms,
                p.effect_ms,
                p.image_ms,
                p.error.flip,
                p.error.rel_mse,
                note(p)
            ));
        }
    }
    for sk in &results.skipped {
        s.push_str(&format!("skipped {} {}: {}\n", sk.effect, sk.technique, sk.reason));
    }
    s
}

/// What the chart of `effect` held fixed: its points' other techniques (the direct and denoise
/// charts hold more than the sweep's common fixed set), else that set.
fn chart_fixed<'a>(results: &'a Results, effect: &str) -> &'a BTreeMap<String, String> {
    results.points.iter().find(|p| p.effect == effect).map_or(&results.fixed, |p| &p.techniques)
}
