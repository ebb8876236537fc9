//! `kiln inspect`: what a file holds.

use kiln_format::{Checksums, KilnFile, sections};
use serde::Serialize;

use crate::cli::InspectArgs;
use crate::exit::{CliResult, format_error};
use crate::output::{print_json, size};

#[derive(Serialize)]
struct SectionJson {
    position: usize,
    kind: String,
    /// Name to pass to `kiln export`, if this reader knows the kind.
    name: Option<&'static str>,
    index: u32,
    version: u16,
    codec: String,
    offset: u64,
    /// Stored bytes.
    size: u64,
    /// Decoded bytes.
    raw_size: u64,
    /// raw_size / size: how much the codec shrank the section (1 for codec none).
    ratio: f64,
    checksum: String,
    checksum_ok: bool,
    content_hash: String,
    /// False for kinds (or versions) this reader does not know and skips.
    understood: bool,
}

#[derive(Serialize)]
struct InspectJson {
    path: String,
    format_version: String,
    file_size: u64,
    flags: u32,
    sections: Vec<SectionJson>,
    /// Null when the manifest cannot be decoded (see `manifest_error`).
    manifest: Option<kiln_format::Manifest>,
    manifest_error: Option<String>,
    summary: Summary,
    /// Voxel grid and line space, when present.
    line_space: Option<LineSpaceJson>,
    /// The irradiance probe volume, when present.
    probes: Option<ProbesJson>,
    /// The environment, when present.
    environment: Option<EnvironmentJson>,
}

#[derive(Serialize)]
struct EnvironmentJson {
    /// Radiance map width and height.
    map: [u32; 2],
    /// Prefiltered level 0's width and height, and the level count.
    filtered: [u32; 3],
    /// Sampling table width and height.
    table: [u32; 2],
    /// Mean radiance (the manifest's sky).
    mean: Option<[f32; 3]>,
    /// Decoded bytes of the four sections.
    bytes: u64,
}

#[derive(Serialize)]
struct ProbesJson {
    dims: [u32; 3],
    spacing: f32,
    probes: u64,
    active: u32,
    layers: u32,
    rays: u32,
    /// Decoded bytes of the four sections.
    bytes: u64,
}

#[derive(Serialize)]
struct LineSpaceJson {
    cells: [u32; 3],
    cell_size: f64,
    shaft_res: u32,
    variants: String,
    slots: u32,
    filled_shafts: u64,
    candidate_entries: u64,
    bytes_voxel_grid: u64,
    bytes_binary: u64,
    bytes_candidates: u64,
    bytes_pnmt: u64,
    /// `full`, `compact` or `compact-no-uv` (null for an undefined layout code).
    pnmt_records: Option<&'static str>,
}

#[derive(Serialize, Default)]
struct Summary {
    vertices: u64,
    triangles: u64,
    materials: u64,
    textures: u64,
    bvh_nodes: u64,
    lights: u64,
    cameras: u64,
}

/// Runs `kiln inspect`.
pub fn run(args: &InspectArgs) -> CliResult {
    let file = KilnFile::open(&args.file, Checksums::Deferred).map_err(|e| format_error(&args.file, e))?;
    let sections: Vec<SectionJson> = file
        .sections()
        .iter()
        .map(|s| {
            let e = &s.entry;
            SectionJson {
                position: s.position,
                kind: e.kind.name(),
                name: s.known.map(|k| k.name),
                index: e.index,
                version: e.version,
                codec: kiln_format::table::Codec::from_u8(e.codec)
                    .map_or_else(|| format!("unknown ({})", e.codec), |c| c.name().to_string()),
                offset: e.offset,
                size: e.size,
                raw_size: e.raw_size,
                ratio: if e.size == 0 { 1.0 } else { e.raw_size as f64 / e.size as f64 },
                checksum: format!("{:016x}", e.checksum),
                checksum_ok: file.verify_section(s.position).is_ok(),
                content_hash: e.content_hash.to_hex(),
                understood: s.known.is_some(),
            }
        })
        .collect();
    let (manifest, manifest_error) = match file.manifest() {
        Ok(m) => (Some(m), None),
        Err(e) => (None, Some(e.to_string())),
    };
    let elements = |kind| {
        file.find(kind, 0)
            .and_then(|s| s.known.map(|k| s.entry.raw_size / k.element_size as u64))
            .unwrap_or(0)
    };
    let summary = Summary {
        vertices: elements(sections::VERTICES),
        triangles: elements(sections::TRIANGLES),
        materials: elements(sections::MATERIALS),
        textures: file.all_of(sections::TEXTURE).len() as u64,
        bvh_nodes: elements(sections::BVH_NODES),
        lights: manifest.as_ref().map_or(0, |m| m.lights.len() as u64),
        cameras: manifest.as_ref().map_or(0, |m| m.cameras.len() as u64),
    };
    // Decoded bytes of sections: what the structures take in memory, whatever the codec.
    let size = |kinds: &[kiln_format::SectionKind]| {
        kinds.iter().filter_map(|&k| file.find(k, 0)).map(|s| s.entry.raw_size).sum::<u64>()
    };
    let line_space = file
        .pod::<kiln_format::linespace::GridHeader>(sections::GRID, 0)
        .ok()
        .flatten()
        .and_then(|g| g.first().copied())
        .map(|g| LineSpaceJson {
            cells: g.dims,
            cell_size: g.cell,
            shaft_res: g.shaft_res,
            variants: crate::settings::variants_name(g.variants),
            slots: g.slots,
            filled_shafts: g.filled,
            candidate_entries: g.entries,
            bytes_voxel_grid: size(&[sections::GRID, sections::VOXEL_OFFSETS, sections::VOXEL_TRIANGLES]),
            bytes_binary: size(&[sections::SHAFT_SLOTS, sections::SHAFT_BITS, sections::SHAFT_RANKS]),
            bytes_candidates: size(&[sections::CANDIDATE_OFFSETS, sections::CANDIDATES]),
            bytes_pnmt: size(&[sections::PNMT]),
            pnmt_records: g.pnmt_records().map(|l| l.name()),
        });
    let probes = file
        .pod::<kiln_format::probes::ProbeHeader>(sections::PROBE_GRID, 0)
        .ok()
        .flatten()
        .and_then(|g| g.first().copied())
        .map(|g| ProbesJson {
            dims: g.dims,
            spacing: g.spacing,
            probes: g.count(),
            active: g.active,
            layers: g.layers,
            rays: g.rays,
            bytes: size(&kiln_format::probes::PROBE_KINDS),
        });
    let environment = file
        .pod::<kiln_format::environment::EnvironmentHeader>(sections::ENVIRONMENT_HEADER, 0)
        .ok()
        .flatten()
        .and_then(|g| g.first().copied())
        .map(|g| EnvironmentJson {
            map: [g.map[0], g.map[1]],
            filtered: [g.filtered[0], g.filtered[1], g.filtered[2]],
            table: [g.table[0], g.table[1]],
            mean: manifest.as_ref().map(|m| m.sky.radiance),
            bytes: size(&kiln_format::environment::ENVIRONMENT_KINDS),
        });
    let h = file.header();
    let report = InspectJson {
        path: args.file.display().to_string(),
        format_version: format!("{}.{}", h.version_major, h.version_minor),
        file_size: h.file_size,
        flags: h.flags,
        sections,
        manifest,
        manifest_error,
        summary,
        line_space,
        probes,
        environment,
    };
    if args.json {
        print_json(&report);
    } else {
        print_text(&report);
    }
    Ok(())
}

fn print_text(r: &InspectJson) {
    print_sections(r);
    if let Some(p) = &r.probes {
        println!(
            "irradiance probes {}x{}x{} every {:.4} units: {} probes, {} on, {} irradiance layer(s), {} paths each, {}",
            p.dims[0],
            p.dims[1],
            p.dims[2],
            p.spacing,
            p.probes,
            p.active,
            p.layers,
            p.rays,
            size(p.bytes)
        );
    }
    if let Some(e) = &r.environment {
        let mean = e
            .mean
            .map_or(String::new(), |m| format!(", mean radiance ({:.4}, {:.4}, {:.4})", m[0], m[1], m[2]));
        println!(
            "environment {}x{}: {} GGX levels from {}x{}, {}x{} sampling table{mean}, {}",
            e.map[0],
            e.map[1],
            e.filtered[2],
            e.filtered[0],
            e.filtered[1],
            e.table[0],
            e.table[1],
            size(e.bytes)
        );
    }
    if let Some(l) = &r.line_space {
        println!(
            "voxel grid {}x{}x{} (cell {:.4}), {} non-empty; line space N = {}, {}: {} filled shafts, {} candidate entries",
            l.cells[0],
            l.cells[1],
            l.cells[2],
            l.cell_size,
            l.slots,
            l.shaft_res,
            l.variants,
            l.filled_shafts,
            l.candidate_entries
        );
        println!(
            "  memory: voxel grid {}, binary {}, candidates {}, PNMT {}{}",
            size(l.bytes_voxel_grid),
            size(l.bytes_binary),
            size(l.bytes_candidates),
            size(l.bytes_pnmt),
            if l.bytes_pnmt > 0 {
                format!(" ({} records)", l.pnmt_records.unwrap_or("undefined"))
            } else {
                String::new()
            }
        );
        if l.filled_shafts > 0 {
            let per = |bytes: u64| bytes as f64 / l.filled_shafts as f64;
            println!(
                "  bytes per filled shaft: binary {:.2}, candidates {:.2}, PNMT {:.2}",
                per(l.bytes_binary),
                per(l.bytes_candidates),
                per(l.bytes_pnmt)
            );
        }
    }
}

fn print_sections(r: &InspectJson) {
    let raw: u64 = r.sections.iter().map(|s| s.raw_size).sum();
    let stored: u64 = r.sections.iter().map(|s| s.size).sum();
    let compressed = r.sections.iter().filter(|s| s.codec != "none").count();
    println!(
        "{}: kiln format {}, {} sections ({compressed} compressed), {}; sections store {} of {} decoded ({:.2}x)",
        r.path,
        r.format_version,
        r.sections.len(),
        size(r.file_size),
        size(stored),
        size(raw),
        if stored == 0 { 1.0 } else { raw as f64 / stored as f64 },
    );
    println!(
        "  {:>3}  {:<4} {:<19} {:>5} {:>3}  {:<5} {:>10} {:>10} {:>10} {:>7}  {:<8} content hash",
        "#", "kind", "name", "index", "ver", "codec", "offset", "size", "decoded", "ratio", "checksum"
    );
    for s in &r.sections {
        println!(
            "  {:>3}  {:<4} {:<19} {:>5} {:>3}  {:<5} {:>10} {:>10} {:>10} {:>7}  {:<8} {}",
            s.position,
            s.kind,
            s.name.unwrap_or("(unknown: skipped)"),
            s.index,
            s.version,
            s.codec,
            format!("{:#x}", s.offset),
            size(s.size),
            size(s.raw_size),
            format!("{:.2}x", s.ratio),
            if s.checksum_ok { "ok" } else { "BAD" },
            &s.content_hash[..16],
        );
    }
    let sm = &r.summary;
    match (&r.manifest, &r.manifest_error) {
        (Some(m), _) => {
            println!("scene '{}', written by {}", m.scene_name, m.generator);
            println!(
                "  {} triangles, {} vertices, {} materials, {} textures, {} BVH nodes, {} lights, {} cameras, {} media",
                sm.triangles,
                sm.vertices,
                sm.materials,
                sm.textures,
                sm.bvh_nodes,
                sm.lights,
                sm.cameras,
                m.media.len()
            );
            let b = &m.bounds;
            println!("  bounds {:?} .. {:?}", b.min, b.max);
            if m.origin != [0.0; 3] {
                let world = |p: [f32; 3]| std::array::from_fn::<f64, 3, _>(|a| f64::from(p[a]) + m.origin[a]);
                println!(
                    "  positions stored relative to origin {:?} (far from the world's origin for the scene's size); \
                     world bounds {:?} .. {:?}",
                    m.origin,
                    world(b.min),
                    world(b.max)
                );
            }
            if m.degenerate_triangles > 0 {
                println!("  {} degenerate triangles dropped at import", m.degenerate_triangles);
            }
            for s in &m.skipped {
                println!("  skipped {}: {}", s.stage, s.reason);
            }
            if !m.inputs.is_empty() {
                println!(
                    "  inputs: {}",
                    m.inputs.iter().map(|i| i.path.as_str()).collect::<Vec<_>>().join(", ")
                );
            }
        }
        (None, Some(e)) => println!("manifest: cannot be decoded: {e}"),
        (None, None) => {}
    }
}
