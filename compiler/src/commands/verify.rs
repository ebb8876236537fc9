//! `kiln verify`: full validation of a file, optionally with a ray check of its BVH.

use kiln_format::{Checksums, KilnFile, SceneView};
use serde::Serialize;

use crate::cli::VerifyArgs;
use crate::exit::{CliError, CliResult, format_error};
use crate::output::print_json;
use kiln_format::linespace::LineSpace;

use crate::raycheck::{BinaryCheck, BvhCheck, CandidateCheck, PnmtCheck, check_bvh, check_line_space};

#[derive(Serialize)]
struct VerifyJson {
    path: String,
    ok: bool,
    /// The first problem found, when not ok.
    error: Option<String>,
    sections: usize,
    /// Compressed sections, each decoded to its declared size after its stored checksum matched.
    compressed_sections: usize,
    /// Sections of kinds this reader does not know: skipped, but their checksums verified.
    skipped_sections: Vec<String>,
    /// The ray check, when `--rays` was given and the file has a BVH.
    bvh: Option<BvhCheck>,
    /// Line-space ray check (grid-specific rays added), when `--rays` was given and the file
    /// has a line space.
    line_space: Option<LineSpaceMeta>,
    /// Candidate lists against brute force.
    candidates: Option<CandidateCheck>,
    /// Binary line space against brute force.
    binary: Option<BinaryCheck>,
    /// PNMT against the exact closest hit.
    pnmt: Option<PnmtCheck>,
}

#[derive(Serialize)]
struct LineSpaceMeta {
    rays: u64,
    seed: u64,
    by_class: std::collections::BTreeMap<String, u64>,
    cells: [u32; 3],
    shaft_res: u32,
}

/// Runs `kiln verify`.
pub fn run(args: &VerifyArgs) -> CliResult {
    let path = args.file.display().to_string();
    let mut report = VerifyJson {
        path,
        ok: false,
        error: None,
        sections: 0,
        compressed_sections: 0,
        skipped_sections: vec![],
        bvh: None,
        line_space: None,
        candidates: None,
        binary: None,
        pnmt: None,
    };
    let outcome = check(args, &mut report);
    if let Err(e) = &outcome {
        report.error = Some(e.message.clone());
    }
    report.ok = outcome.is_ok();
    if args.json {
        print_json(&report);
    } else if outcome.is_ok() {
        for s in &report.skipped_sections {
            eprintln!("warning: {}: section {s} is unknown to this kiln; skipped", report.path);
        }
        if let Some(b) = &report.bvh {
            println!(
                "{}: bvh: {} rays (seed {}), {} hits, {} ties on shared edges, {} mismatches",
                report.path, b.rays, b.seed, b.hits, b.ties, b.mismatches
            );
        }
        if let Some(c) = &report.candidates {
            println!(
                "{}: candidates: {} mismatches, {} ties, {} any-hit mismatches",
                report.path, c.mismatches, c.ties, c.any_hit_mismatches
            );
        }
        if let Some(b) = &report.binary {
            println!(
                "{}: binary: {} false misses, {} false hits ({} rays hit)",
                report.path, b.false_misses, b.false_hits, b.hits
            );
        }
        if let Some(p) = &report.pnmt {
            println!(
                "{}: pnmt: {} hit disagreements ({} only PNMT, {} only exact); position error median {:.3e} p99 {:.3e} max {:.3e}; normal error median {:.2}° p99 {:.2}° max {:.2}°",
                report.path,
                p.hit_disagreements,
                p.pnmt_only,
                p.reference_only,
                p.position_error.median,
                p.position_error.p99,
                p.position_error.max,
                p.normal_error_degrees.median,
                p.normal_error_degrees.p99,
                p.normal_error_degrees.max
            );
        }
        println!(
            "{}: ok ({} sections, {} compressed)",
            report.path, report.sections, report.compressed_sections
        );
    }
    outcome
}

fn check(args: &VerifyArgs, report: &mut VerifyJson) -> CliResult {
    let file = KilnFile::open(&args.file, Checksums::Eager).map_err(|e| format_error(&args.file, e))?;
    // Opening verified every stored checksum; now every compressed section of a known kind is
    // decoded (one frame, exactly raw_size bytes, zstd's checksum of the decoded bytes), before
    // the content checks below read the decoded bytes, so that a section no check reads is
    // decoded too; sections whose length a record fixes are first compared with it, undecoded.
    kiln_format::scene::check_declared_sizes(&file).map_err(|e| format_error(&args.file, e))?;
    for s in file.sections().iter().filter(|s| s.known.is_some()) {
        file.decode_section(s.position).map_err(|e| format_error(&args.file, e))?;
        if s.entry.codec != kiln_format::table::Codec::None as u8 {
            report.compressed_sections += 1;
        }
    }
    let view = SceneView::new(&file).map_err(|e| format_error(&args.file, e))?;
    // Texture headers (pixel format, swizzle) and exact lengths are read with the texels.
    for i in 0..view.manifest.textures.len() {
        view.texture(i).map_err(|e| format_error(&args.file, e))?;
    }
    let line_space = LineSpace::new(&file, view.triangles.len(), view.materials.len())
        .map_err(|e| format_error(&args.file, e))?;
    if let Some(ls) = &line_space {
        ls.check_against(&view.manifest.bounds, view.vertices, view.triangles)
            .map_err(|e| format_error(&args.file, e))?;
    }
    report.sections = file.sections().len();
    report.skipped_sections = file
        .skipped()
        .map(|s| format!("{}#{} (version {})", s.entry.kind, s.entry.index, s.entry.version))
        .collect();
    if let Some(n) = args.rays {
        if view.bvh.is_empty() || view.triangles.is_empty() {
            return Err(CliError::input(format!(
                "{}: --rays needs a BVH and triangles; the file has none",
                report.path
            )));
        }
        if let Some(ls) = line_space.as_ref().filter(|l| l.header.variants != 0) {
            let c = check_line_space(&view, ls, n, args.seed);
            report.line_space = Some(LineSpaceMeta {
                rays: c.rays,
                seed: c.seed,
                by_class: c.by_class.clone(),
                cells: ls.header.dims,
                shaft_res: ls.header.shaft_res,
            });
            let bad_candidates = c.candidates.as_ref().map_or(0, |c| c.mismatches + c.any_hit_mismatches);
            let false_misses = c.binary.false_misses;
            let first = c
                .candidates
                .as_ref()
                .and_then(|c| c.examples.first().cloned())
                .or_else(|| c.binary.examples.first().cloned())
                .unwrap_or_default();
            report.candidates = c.candidates;
            report.binary = Some(c.binary);
            report.pnmt = c.pnmt;
            if bad_candidates > 0 || false_misses > 0 {
                return Err(CliError::input(format!(
                    "{}: line space: {bad_candidates} candidate mismatches and {false_misses} binary false misses; first: {first}",
                    report.path
                )));
            }
        }
        let b = check_bvh(&view, n, args.seed);
        let bad = b.mismatches;
        let first = b.examples.first().cloned().unwrap_or_default();
        report.bvh = Some(b);
        if bad > 0 {
            return Err(CliError::input(format!(
                "{}: section CWBV: {bad} of {n} rays disagree with brute force; first: {first}",
                report.path
            )));
        }
    }
    Ok(())
}
