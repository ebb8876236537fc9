//! `kiln-bench` as a user runs it, on the built-in Cornell box at 64 × 48 on whatever Vulkan
//! device is here (lavapipe in CI), checked from the files it writes:
//!
//! - every effect with two or more techniques has a Pareto front of two or more points; RT AO's
//!   error falls with every step of frames accumulated (1, 4, 16, 64) and ends near the
//!   reference's noise floor; shadows "none" (a deliberately wrong technique) lies far above the
//!   front at its cost;
//! - the mean FLIP it reports is recomputed from the images it kept (`--keep-images`) by
//!   `flip-evaluator` (NVIDIA's implementation, from PyPI), and RMSE here with its own
//!   arithmetic;
//! - results.csv says what results.json says; charts and index.html are there;
//! - bad input is refused before any work, with the reason.
//!
//! Without a Vulkan device (or flip-evaluator) the tests say so and pass, unless
//! `KILN_REQUIRE_VULKAN` (or `KILN_REQUIRE_MITSUBA`) is set, as `.ci/run` does.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use clap::Parser;
use serde_json::Value;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn vulkan() -> bool {
    let required = std::env::var_os("KILN_REQUIRE_VULKAN").is_some();
    if kiln_player::gpu::list_devices().map_or(true, |d| d.is_empty()) {
        assert!(!required, "no Vulkan device but KILN_REQUIRE_VULKAN is set");
        eprintln!("skipping: no Vulkan device");
        return false;
    }
    true
}

/// The Python with flip-evaluator and numpy (`.venv-mitsuba`, which `.ci/run` makes).
fn flip_python() -> Option<PathBuf> {
    let python = std::env::var_os("KILN_MITSUBA_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace().join(".venv-mitsuba/bin/python"));
    let ok = Command::new(&python)
        .args(["-c", "import flip_evaluator, numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            std::env::var_os("KILN_REQUIRE_MITSUBA").is_none(),
            "{} cannot import flip_evaluator and numpy, but KILN_REQUIRE_MITSUBA is set",
            python.display()
        );
        eprintln!("skipping the FLIP recomputation: no flip-evaluator (run .ci/run)");
        return None;
    }
    Some(python)
}

/// A temporary folder with the demo scene compiled into it.
fn demo() -> &'static (tempfile::TempDir, PathBuf) {
    static DEMO: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    DEMO.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("demo.kiln");
        let cli = kiln_compiler::cli::Cli::parse_from([
            "kiln",
            "demo",
            "-q",
            "--shaft-variants",
            "none",
            "-o",
            file.to_str().unwrap(),
        ]);
        kiln_compiler::commands::run(cli).unwrap();
        (dir, file)
    })
}

fn bench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kiln-bench")).args(args).output().unwrap()
}

/// The sweep the tests read (run once): shadows, AO and two frame presets.
fn sweep() -> &'static (tempfile::TempDir, Value) {
    static SWEEP: OnceLock<(tempfile::TempDir, Value)> = OnceLock::new();
    SWEEP.get_or_init(|| {
        let out = tempfile::tempdir().unwrap();
        let file = demo().1.to_str().unwrap().to_string();
        let o = bench(&[
            &file,
            "--size",
            "64x48",
            "--effects",
            "shadows,ao,frame",
            "--techniques",
            "shadows:none,shadows:shadowmap,shadows:rt,ao:none,ao:rt,frame:baked,frame:rt",
            "--reference-spp",
            "256",
            "--timing-frames",
            "3",
            "--warmup",
            "1",
            "--keep-images",
            "--validate",
            "--json",
            "--out",
            out.path().to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "kiln-bench failed ({:?}): {stderr}", o.status);
        let printed: Value = serde_json::from_slice(&o.stdout).expect("--json prints JSON");
        let written: Value =
            serde_json::from_str(&std::fs::read_to_string(out.path().join("results.json")).unwrap()).unwrap();
        assert_eq!(printed, written, "--json prints what results.json holds");
        (out, written)
    })
}

fn points<'a>(results: &'a Value, effect: &str) -> Vec<&'a Value> {
    results["points"].as_array().unwrap().iter().filter(|p| p["effect"] == effect).collect()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("{v} is not a number"))
}

#[test]
fn every_effect_with_choices_has_a_front_and_wrong_techniques_lie_off_it() {
    if !vulkan() {
        return;
    }
    let (out, r) = sweep();
    for effect in ["shadows", "ao", "frame"] {
        let ps = points(r, effect);
        let techniques: std::collections::BTreeSet<&str> = ps.iter().map(|p| p["technique"].as_str().unwrap()).collect();
        assert!(techniques.len() >= 2, "{effect}: {techniques:?}");
        // The front, recomputed here from the definition: no other point at most as slow and
        // at most as wrong with one of them strictly.
        let dominated = |p: &Value| {
            ps.iter().any(|q| {
                let (px, py, qx, qy) = (f(&p["image_ms"]), f(&p["error"]["flip"]), f(&q["image_ms"]), f(&q["error"]["flip"]));
                qx <= px && qy <= py && (qx < px || qy < py)
            })
        };
        let front: Vec<&&Value> = ps.iter().filter(|p| !dominated(p)).collect();
        assert!(front.len() >= 2, "{effect}: front {front:?}");
        for p in &ps {
            assert_eq!(p["on_front"].as_bool().unwrap(), !dominated(p), "{effect} {}", p["label"]);
        }
        assert!(out.path().join(format!("{effect}.svg")).is_file() && out.path().join(format!("{effect}.png")).is_file());
    }
    // Shadows "none" is cheap and wrong: the shadow-mapped frame, at most twice its time, has at
    // most half its error.
    let ps = points(r, "shadows");
    let none = ps.iter().find(|p| p["technique"] == "none").unwrap();
    let map = ps.iter().find(|p| p["technique"] == "shadowmap").unwrap();
    assert!(f(&map["image_ms"]) <= 2.0 * f(&none["image_ms"]), "{map}\n{none}");
    assert!(f(&map["error"]["flip"]) * 2.0 <= f(&none["error"]["flip"]), "{map}\n{none}");
    let html = std::fs::read_to_string(out.path().join("index.html")).unwrap();
    for effect in ["shadows", "ao", "frame"] {
        assert!(html.contains(&format!("{effect}.svg")), "index.html shows {effect}.svg");
    }
}

#[test]
fn rt_ao_converges_with_frames_accumulated_to_the_noise_floor() {
    if !vulkan() {
        return;
    }
    let (_, r) = sweep();
    let mut ao: Vec<&Value> = points(r, "ao").into_iter().filter(|p| p["technique"] == "rt").collect();
    ao.sort_by_key(|p| p["frames"].as_u64().unwrap());
    let frames: Vec<u64> = ao.iter().map(|p| p["frames"].as_u64().unwrap()).collect();
    assert_eq!(frames, [1, 4, 16, 64]);
    let flip: Vec<f64> = ao.iter().map(|p| f(&p["error"]["flip"])).collect();
    let rmse: Vec<f64> = ao.iter().map(|p| f(&p["error"]["rmse"])).collect();
    for w in flip.windows(2).chain(rmse.windows(2)) {
        assert!(w[1] < w[0], "error must fall with every step of accumulation: flip {flip:?}, rmse {rmse:?}");
    }
    let floor = f(&r["references"][0]["noise_floor"]["flip"]);
    assert!(flip[3] < 1.5 * floor, "64 frames: FLIP {} vs the noise floor {floor}", flip[3]);
    // Times: one frame costs the same whatever is accumulated, so the image time grows with it.
    let t: Vec<f64> = ao.iter().map(|p| f(&p["image_ms"]) / f(&p["frame_ms"])).collect();
    assert_eq!(t, [1.0, 4.0, 16.0, 64.0]);
}

fn read_exr(path: &Path) -> Vec<f32> {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).into_rgb32f().into_raw()
}

#[test]
fn reported_errors_are_recomputed_from_the_kept_images() {
    if !vulkan() {
        return;
    }
    let (out, r) = sweep();
    let images = out.path().join("images");
    let reference_file = images.join("file-reference.exr");
    let reference = read_exr(&reference_file);
    let mut pairs = Vec::new();
    for p in r["points"].as_array().unwrap() {
        let name = format!("file-{}-{}", p["effect"].as_str().unwrap(), p["label"].as_str().unwrap())
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_') { c } else { '_' })
            .collect::<String>();
        let path = images.join(format!("{name}.exr"));
        let test = read_exr(&path);
        assert_eq!(test.len(), reference.len());
        let mse = test.iter().zip(&reference).map(|(t, r)| ((t - r) as f64).powi(2)).sum::<f64>() / test.len() as f64;
        let rel = test
            .iter()
            .zip(&reference)
            .map(|(t, r)| ((t - r) as f64).powi(2) / ((*r as f64).powi(2) + 1e-2))
            .sum::<f64>()
            / test.len() as f64;
        assert!((mse.sqrt() - f(&p["error"]["rmse"])).abs() <= 1e-6 * mse.sqrt().max(1e-3), "{path:?} rmse");
        assert!((rel - f(&p["error"]["rel_mse"])).abs() <= 1e-6 * rel.max(1e-3), "{path:?} relmse");
        pairs.push((path, f(&p["error"]["flip"])));
    }
    let Some(python) = flip_python() else { return };
    let script = "import sys, flip_evaluator as flip\n\
                  ref = sys.argv[1]\n\
                  for test in sys.argv[2:]:\n    \
                      _, mean, _ = flip.evaluate(ref, test, 'HDR')\n    \
                      print(repr(float(mean)))\n";
    let o = Command::new(python)
        .arg("-c")
        .arg(script)
        .arg(&reference_file)
        .args(pairs.iter().map(|p| &p.0))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let theirs: Vec<f64> = String::from_utf8_lossy(&o.stdout).lines().map(|l| l.trim().parse().unwrap()).collect();
    assert_eq!(theirs.len(), pairs.len());
    for ((path, ours), theirs) in pairs.iter().zip(&theirs) {
        assert!((ours - theirs).abs() <= 1e-3, "{}: kiln-bench FLIP {ours}, flip-evaluator {theirs}", path.display());
    }
}

/// A CSV line split at commas outside double quotes ("" inside quotes is a quote).
fn split_csv(line: &str) -> Vec<String> {
    let (mut fields, mut cur, mut quoted, mut chars) = (Vec::new(), String::new(), false, line.chars().peekable());
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    fields.push(cur);
    fields
}

#[test]
fn csv_says_what_json_says() {
    if !vulkan() {
        return;
    }
    let (out, r) = sweep();
    let csv = std::fs::read_to_string(out.path().join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header = split_csv(lines.next().unwrap());
    let col = |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
    let rows: Vec<Vec<String>> = lines.map(split_csv).collect();
    let points = r["points"].as_array().unwrap();
    assert_eq!(rows.len(), points.len());
    for (row, p) in rows.iter().zip(points) {
        assert_eq!(row.len(), header.len());
        for (column, value) in [
            ("effect", &p["effect"]),
            ("technique", &p["technique"]),
            ("label", &p["label"]),
            ("camera", &p["camera"]),
        ] {
            assert_eq!(row[col(column)], value.as_str().unwrap());
        }
        for (column, value) in [
            ("frames", &p["frames"]),
            ("frame_ms", &p["frame_ms"]),
            ("image_ms", &p["image_ms"]),
            ("flip", &p["error"]["flip"]),
            ("rel_mse", &p["error"]["rel_mse"]),
            ("rmse", &p["error"]["rmse"]),
            ("reference_spp", &p["reference_spp"]),
            ("floor_flip", &p["noise_floor"]["flip"]),
        ] {
            assert_eq!(row[col(column)].parse::<f64>().unwrap(), f(value), "{column}");
        }
        assert_eq!(row[col("on_front")], p["on_front"].to_string());
        assert_eq!(row[col("gpu_uuid")], r["device"]["uuid"].as_str().unwrap());
        assert_eq!(row[col("scene_hash")], r["scene"]["content_hash"].as_str().unwrap());
    }
}

#[test]
fn bad_requests_are_refused_before_any_work() {
    let file = if vulkan() { demo().1.to_str().unwrap().to_string() } else { "missing.kiln".into() };
    let out = tempfile::tempdir().unwrap();
    let o = out.path().to_str().unwrap();
    for (args, says) in [
        (vec![file.as_str(), "--size", "0x48", "--out", o], "--size"),
        (vec![file.as_str(), "--effects", "fog", "--out", o], "no effect 'fog'"),
        (vec![file.as_str(), "--techniques", "ao:shadowmap", "--out", o], "ao:shadowmap"),
        (vec![file.as_str(), "--reference-spp", "1", "--out", o], "reference-spp"),
        (vec![file.as_str(), "--camera", "0,0,0,0,0,0", "--out", o], "position and target must differ"),
        (vec!["/nonexistent/x.kiln", "--out", o], "x.kiln"),
    ] {
        let r = bench(&args);
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{args:?} was accepted");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert!(!out.path().join("reference").exists(), "{args:?} started work");
    }
}
