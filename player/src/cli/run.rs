//! Carrying out a parsed `kiln-play` command line: the device list, the reference path tracer,
//! the benchmarks, a headless render or the window.

use std::time::Instant;

use super::Args;
use crate::bench;
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::list_devices;
use crate::headless;
use crate::session::SessionOptions;
use crate::window;

fn run_reference(args: &Args, options: &SessionOptions, start: Instant) -> PlayResult {
    let output =
        args.output.as_ref().ok_or_else(|| PlayError::new(Exit::Usage, "--reference needs -o OUT.exr"))?;
    if crate::image_out::OutputKind::of(output)? != crate::image_out::OutputKind::Exr {
        return Err(PlayError::new(Exit::Usage, "--reference writes linear radiance: give -o OUT.exr"));
    }
    let (report, rgb) = crate::reference::render(options, args.spp, start)?;
    if rgb.iter().any(|v| !v.is_finite()) {
        return Err(PlayError::new(Exit::Gpu, "the reference image holds NaN or infinite values"));
    }
    crate::reference::write_exr(output, report.width, report.height, &rgb, report.spp)?;
    eprintln!(
        "wrote {} ({}x{}, {} spp) in {:.1} s: {:.2} M samples/s on {}",
        output.display(),
        report.width,
        report.height,
        report.spp,
        report.seconds,
        report.samples_per_second * 1e-6,
        report.device
    );
    Ok(())
}

fn validation_verdict(errors: u32) -> PlayResult {
    if errors > 0 {
        return Err(PlayError::new(Exit::Gpu, format!("the validation layer reported {errors} error(s)")));
    }
    Ok(())
}

/// Runs the command line; `start` is the process start.
pub fn run(args: Args, start: Instant) -> PlayResult {
    if args.list_devices {
        for (name, kind, version) in list_devices()? {
            println!("{name}  ({kind}, Vulkan {version})");
        }
        return Ok(());
    }
    let Some(file) = args.file.clone() else {
        println!(
            "kiln-play {} (format {}.{}): give a .kiln file to play; --help explains",
            env!("CARGO_PKG_VERSION"),
            kiln_format::header::VERSION_MAJOR,
            kiln_format::header::VERSION_MINOR
        );
        return Ok(());
    };
    let options = args.session(file)?;
    if args.reference {
        return run_reference(&args, &options, start);
    }
    if args.json && !args.bench && !args.bench_rays {
        return Err(PlayError::new(Exit::Usage, "--json goes with --bench or --bench-rays"));
    }
    if args.bench_rays {
        let report = crate::raybench::run(&options, args.frames.unwrap_or(20), start)?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&report).unwrap_or_default());
        } else {
            print!("{}", report.table());
        }
        return Ok(());
    }
    if args.bench {
        let report = bench::run(&options, args.warmup, args.frames.unwrap_or(100), start)?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&report).unwrap_or_default());
        } else {
            print!("{}", report.table());
        }
        return validation_verdict(report.validation_errors);
    }
    if args.headless || args.output.is_some() {
        if args.output.is_none() {
            eprintln!("note: no -o given; rendering without writing an image");
        }
        let result = headless::run(&options, args.frames.unwrap_or(1), args.output.as_deref(), start)?;
        let s = &result.session;
        for w in &s.warnings {
            eprintln!("warning: {w}");
        }
        for n in &s.notes {
            eprintln!("note: {n}");
        }
        if let Some(out) = &args.output {
            // Behind a fallback, its first frame and the chosen techniques' are both timed.
            let chosen = if s.times.fallback.is_empty() {
                String::new()
            } else {
                format!(", {:.0} ms with the chosen techniques", s.times.full_frame_since_start_ms)
            };
            eprintln!(
                "wrote {} ({}x{}, {}) in {:.0} ms (first frame {:.0} ms after start{chosen}; device {})",
                out.display(),
                options.width,
                options.height,
                s.scene.manifest.scene_name,
                s.since_start_ms(),
                s.times.first_frame_since_start_ms,
                s.gpu.name
            );
        }
        if result.non_finite > 0 {
            return Err(PlayError::new(
                Exit::Gpu,
                format!("{} pixel(s) of the frame are NaN or infinite", result.non_finite),
            ));
        }
        return validation_verdict(s.validation_errors());
    }
    window::run(options, args.frames, start)
}
