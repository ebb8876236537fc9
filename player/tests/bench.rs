//! `kiln-bench` as a user runs it, at 64 × 48 on whatever Vulkan device is here (lavapipe in
//! CI), checked from the files it writes:
//!
//! - on the built-in Cornell box, every effect with two or more techniques has a Pareto front
//!   of two or more points, and shadows "none" (a deliberately wrong technique) lies far above
//!   the front at its cost;
//! - on a sky-lit corner (written here: a grey Lambertian floor, wall and box under a white sky,
//!   no lights), RT AO with full occlusion is exactly what the frame's sky term needs, so its
//!   error must fall with every step of frames accumulated (1, 4, 16, 64) into the reference's
//!   noise-floor band (the Cornell box has no sky: AO changes nothing there);
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

use serde_json::Value;

mod common;
use common::kiln;
use kiln_test_support::{chromium, flip_python, gpu_test, mse, read_exr, require, screenshot, vulkan};

/// A temporary folder with the demo scene compiled into it.
fn demo() -> &'static (tempfile::TempDir, PathBuf) {
    static DEMO: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    DEMO.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("demo.kiln");
        kiln(&["demo", "-q", "--shaft-variants", "none", "-o", file.to_str().unwrap()]);
        (dir, file)
    })
}

fn bench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kiln-bench")).args(args).output().unwrap()
}

/// The sky-lit corner, compiled.
fn sky_scene() -> &'static (tempfile::TempDir, PathBuf) {
    static SKY: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    SKY.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let mut obj = String::from("mtllib scene.mtl\nusemtl grey\n");
        let mut faces = String::new();
        let mut n = 0;
        let mut quad = |c: [[f32; 3]; 4]| {
            for p in c {
                obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
            }
            faces.push_str(&format!("f {} {} {} {}\n", n + 1, n + 2, n + 3, n + 4));
            n += 4;
        };
        quad([[-2.0, 0.0, 2.0], [2.0, 0.0, 2.0], [2.0, 0.0, -1.0], [-2.0, 0.0, -1.0]]);
        quad([[-2.0, 0.0, -1.0], [2.0, 0.0, -1.0], [2.0, 2.0, -1.0], [-2.0, 2.0, -1.0]]);
        let (x0, x1, y1, z0, z1) = (-0.2, 0.6, 0.8, -0.4, 0.4);
        quad([[x0, y1, z1], [x1, y1, z1], [x1, y1, z0], [x0, y1, z0]]);
        quad([[x0, 0.0, z1], [x1, 0.0, z1], [x1, y1, z1], [x0, y1, z1]]);
        quad([[x1, 0.0, z1], [x1, 0.0, z0], [x1, y1, z0], [x1, y1, z1]]);
        quad([[x0, 0.0, z0], [x0, 0.0, z1], [x0, y1, z1], [x0, y1, z0]]);
        quad([[x1, 0.0, z0], [x0, 0.0, z0], [x0, y1, z0], [x1, y1, z0]]);
        obj.push_str(&faces);
        std::fs::write(dir.path().join("scene.obj"), obj).unwrap();
        std::fs::write(dir.path().join("scene.mtl"), "newmtl grey\nKd 0.6 0.6 0.6\n").unwrap();
        let sidecar = "[camera]\nposition = [0.0, 1.6, 3.2]\ntarget = [0.0, 0.4, 0.0]\nvfov_degrees = 45.0\n\n\
                       [sky]\nradiance = [1.0, 1.0, 1.0]\n\n[material.\"grey\"]\ndiffuse_only = true\n";
        std::fs::write(dir.path().join("scene.toml"), sidecar).unwrap();
        let file = dir.path().join("sky.kiln");
        let (obj, toml) = (dir.path().join("scene.obj"), dir.path().join("scene.toml"));
        kiln(&[
            "compile",
            obj.to_str().unwrap(),
            "--config",
            toml.to_str().unwrap(),
            "-q",
            "--shaft-variants",
            "none",
            "-o",
            file.to_str().unwrap(),
        ]);
        (dir, file)
    })
}

/// Runs a sweep at 64 × 48 with quick timing and the images kept; returns the output folder
/// and results.json (which must equal what --json printed).
fn run_sweep(file: &Path, effects: &str, techniques: &str) -> (tempfile::TempDir, Value) {
    let out = tempfile::tempdir().unwrap();
    let o = bench(&[
        file.to_str().unwrap(),
        "--size",
        "64x48",
        "--effects",
        effects,
        "--techniques",
        techniques,
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
}

/// The AO sweep of the sky-lit corner (run once).
fn sky_sweep() -> &'static (tempfile::TempDir, Value) {
    static SWEEP: OnceLock<(tempfile::TempDir, Value)> = OnceLock::new();
    SWEEP.get_or_init(|| run_sweep(&sky_scene().1, "ao", "ao:none,ao:rt"))
}

/// The demo sweep the tests read (run once): shadows and two frame presets.
fn sweep() -> &'static (tempfile::TempDir, Value) {
    static SWEEP: OnceLock<(tempfile::TempDir, Value)> = OnceLock::new();
    SWEEP.get_or_init(|| {
        run_sweep(
            &demo().1,
            "shadows,frame",
            "shadows:none,shadows:shadowmap,shadows:rt,frame:baked,frame:rt",
        )
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
    require!(vulkan());
    let (out, r) = sweep();
    for effect in ["shadows", "frame"] {
        let ps = points(r, effect);
        let techniques: std::collections::BTreeSet<&str> =
            ps.iter().map(|p| p["technique"].as_str().unwrap()).collect();
        assert!(techniques.len() >= 2, "{effect}: {techniques:?}");
        // The front, recomputed here from the definition: no other point at most as slow and
        // at most as wrong with one of them strictly.
        let dominated = |p: &Value| {
            ps.iter().any(|q| {
                let (px, py, qx, qy) =
                    (f(&p["image_ms"]), f(&p["error"]["flip"]), f(&q["image_ms"]), f(&q["error"]["flip"]));
                qx <= px && qy <= py && (qx < px || qy < py)
            })
        };
        let front: Vec<&&Value> = ps.iter().filter(|p| !dominated(p)).collect();
        assert!(front.len() >= 2, "{effect}: front {front:?}");
        for p in &ps {
            assert_eq!(p["on_front"].as_bool().unwrap(), !dominated(p), "{effect} {}", p["label"]);
        }
        assert!(
            out.path().join(format!("{effect}.svg")).is_file()
                && out.path().join(format!("{effect}.png")).is_file()
        );
    }
    // Shadows "none" is cheap and wrong: converged ray-traced shadows have a third of its
    // relative error. (Mean FLIP at 64 × 48 is dominated by the unfiltered edges every frame
    // technique shares, and ranks the shadow map's per-pixel PCSS noise below no shadows at all;
    // see the sky-lit AO chart for the FLIP version of this check.)
    let ps = points(r, "shadows");
    let none = ps.iter().find(|p| p["technique"] == "none").unwrap();
    let rt = ps.iter().find(|p| p["technique"] == "rt" && p["frames"] == 64).unwrap();
    assert!(f(&rt["error"]["rel_mse"]) * 3.0 <= f(&none["error"]["rel_mse"]), "{rt}\n{none}");
    let html = std::fs::read_to_string(out.path().join("index.html")).unwrap();
    for effect in ["shadows", "frame"] {
        assert!(html.contains(&format!("{effect}.svg")), "index.html shows {effect}.svg");
    }
}

#[test]
fn rt_ao_converges_with_frames_accumulated_to_the_noise_floor() {
    require!(vulkan());
    let (_, r) = sky_sweep();
    assert!(points(r, "ao").len() > 4, "every reach is swept");
    // Reach 100 diagonals: every hit occludes fully, the sky's visibility.
    let mut ao: Vec<&Value> = points(r, "ao")
        .into_iter()
        .filter(|p| p["technique"] == "rt" && p["knobs"]["ao-reach"] == "100")
        .collect();
    ao.sort_by_key(|p| p["frames"].as_u64().unwrap());
    let frames: Vec<u64> = ao.iter().map(|p| p["frames"].as_u64().unwrap()).collect();
    assert_eq!(frames, [1, 4, 16, 64]);
    let flip: Vec<f64> = ao.iter().map(|p| f(&p["error"]["flip"])).collect();
    let rmse: Vec<f64> = ao.iter().map(|p| f(&p["error"]["rmse"])).collect();
    for w in flip.windows(2).chain(rmse.windows(2)) {
        assert!(w[1] < w[0], "error must fall with every step of accumulation: flip {flip:?}, rmse {rmse:?}");
    }
    let reference = &r["references"][0];
    assert_eq!(reference["bounces"], 1, "AO is measured against direct light");
    let floor = f(&reference["noise_floor"]["flip"]);
    assert!(flip[3] < 1.5 * floor, "64 frames: FLIP {} vs the noise floor {floor}", flip[3]);
    // AO "none" (the sky seen through every wall) lands far from the front: the converged
    // technique on the front has a quarter of its error.
    let none = points(r, "ao").into_iter().find(|p| p["technique"] == "none").unwrap();
    let best = points(r, "ao")
        .into_iter()
        .filter(|p| p["on_front"] == true)
        .map(|p| f(&p["error"]["flip"]))
        .fold(f64::MAX, f64::min);
    assert!(4.0 * best <= f(&none["error"]["flip"]), "none {none}, best on the front {best}");
    // Times: one frame costs the same whatever is accumulated, so the image time grows with it.
    for (p, n) in ao.iter().zip([1.0, 4.0, 16.0, 64.0]) {
        assert!((f(&p["image_ms"]) - n * f(&p["frame_ms"])).abs() <= 1e-9 * f(&p["image_ms"]), "{p}");
    }
}

#[test]
fn reported_errors_are_recomputed_from_the_kept_images() {
    require!(vulkan());
    let mut pairs = Vec::new();
    for (out, r) in [sweep(), sky_sweep()] {
        pairs.extend(recompute(out.path(), r));
        // The noise floor: the two cached halves, RMSE here (halved: the mean of both has half
        // the halves' difference's deviation), FLIP by flip-evaluator below.
        for reference in r["references"].as_array().unwrap() {
            let key = reference["key"].as_str().unwrap();
            let [a, b] = ["a", "b"].map(|h| out.path().join("reference").join(format!("{key}-{h}.exr")));
            let mse = mse(&read_exr(&a), &read_exr(&b));
            let reported = f(&reference["noise_floor"]["rmse"]);
            assert!((mse.sqrt() / 2.0 - reported).abs() <= 1e-6 * reported, "{key}: floor {reported}");
            pairs.push((a, b, f(&reference["noise_floor"]["flip"])));
        }
    }
    let python = require!(flip_python());
    // flip-evaluator, one process per reference image.
    let mut by_reference: std::collections::BTreeMap<&PathBuf, Vec<&(PathBuf, PathBuf, f64)>> =
        Default::default();
    for p in &pairs {
        by_reference.entry(&p.0).or_default().push(p);
    }
    // The images go over as raw little-endian f32 (flip-evaluator's own EXR reader crashes on
    // RGB-only files), read here by the `image` crate, not by the code under test.
    let raw = |exr: &Path| {
        let path = exr.with_extension("f32");
        let bytes: Vec<u8> = read_exr(exr).iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(&path, bytes).unwrap();
        path
    };
    let script = "import sys, numpy as np, flip_evaluator as flip\n\
                  h, w = int(sys.argv[1]), int(sys.argv[2])\n\
                  load = lambda p: np.fromfile(p, dtype='<f4').reshape(h, w, 3)\n\
                  ref = load(sys.argv[3])\n\
                  for test in sys.argv[4:]:\n    \
                      errmap, mean, _ = flip.evaluate(ref, load(test), 'HDR', applyMagma=False)\n    \
                      np.asarray(errmap, dtype='<f4').tofile(test + '.map')\n    \
                      print(repr(float(mean)))\n";
    for (reference, tests) in by_reference {
        let o = Command::new(&python)
            .arg("-c")
            .arg(script)
            .args(["48", "64"])
            .arg(raw(reference))
            .args(tests.iter().map(|p| raw(&p.1)))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let theirs: Vec<f64> =
            String::from_utf8_lossy(&o.stdout).lines().map(|l| l.trim().parse().unwrap()).collect();
        assert_eq!(theirs.len(), tests.len());
        for ((_, path, ours), theirs) in tests.iter().map(|p| (&p.0, &p.1, p.2)).zip(&theirs) {
            assert!(
                (ours - theirs).abs() <= 1e-3,
                "{}: kiln-bench FLIP {ours}, flip-evaluator {theirs}",
                path.display()
            );
            // The measured images have maps (the noise floor's halves under reference/ do not).
            if path.parent().is_some_and(|d| d.ends_with("images")) {
                check_error_map(path);
            }
        }
    }
    // `--diff` on a kept pair prints what the sweep reported (itself checked above).
    let (reference, image, flip) = &pairs[0];
    let dir = tempfile::tempdir().unwrap();
    let o = bench(&[
        "--diff",
        reference.to_str().unwrap(),
        image.to_str().unwrap(),
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}{}", String::from_utf8_lossy(&o.stderr));
    let printed: f64 = text.split_whitespace().nth(1).and_then(|v| v.parse().ok()).unwrap_or(f64::NAN);
    assert!((printed - flip).abs() <= 1e-4, "--diff printed {text:?}, the sweep {flip}");
    assert!(dir.path().join("flip.png").is_file(), "--diff wrote no map");
    // A reader that has gone (`kiln-bench --diff A B | head -0`): quiet, no panic.
    let mut child = Command::new(env!("CARGO_BIN_EXE_kiln-bench"))
        .args([
            "--diff",
            reference.to_str().unwrap(),
            image.to_str().unwrap(),
            "-o",
            dir.path().to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked") && o.status.code() != Some(101), "{:?}: {stderr}", o.status);
}

/// The heat map kept beside a measured image (`...-flip.png`: 0 black, 1/3 red, 2/3 yellow, 1
/// white, so the channels' sum over 765 is the value) against flip-evaluator's per-pixel map
/// (`IMAGE.f32.map`, written by the script above), within the PNG's 8-bit steps.
fn check_error_map(image: &Path) {
    let name = image.file_stem().unwrap().to_string_lossy();
    let png = image.with_file_name(format!("{name}-flip.png"));
    let heat = image::open(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display())).into_rgb8();
    let theirs: Vec<f32> = std::fs::read(image.with_extension("f32.map"))
        .unwrap()
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert_eq!(theirs.len(), heat.pixels().len(), "{}", png.display());
    let worst = heat
        .pixels()
        .zip(&theirs)
        .map(|(p, t)| ((p[0] as f32 + p[1] as f32 + p[2] as f32) / 765.0 - t.clamp(0.0, 1.0)).abs())
        .fold(0.0f32, f32::max);
    assert!(worst <= 2.0 / 255.0, "{}: a pixel differs from flip-evaluator's map by {worst}", png.display());
}

/// RMSE and relMSE of every point recomputed from the kept images; returns (reference image,
/// point image, reported FLIP) for each.
fn recompute(out: &Path, r: &Value) -> Vec<(PathBuf, PathBuf, f64)> {
    let images = out.join("images");
    let mut pairs = Vec::new();
    for p in r["points"].as_array().unwrap() {
        let reference_file = images.join(format!("file-reference-{}.exr", p["reference_bounces"]));
        let reference = read_exr(&reference_file);
        let name = format!("file-{}-{}", p["effect"].as_str().unwrap(), p["label"].as_str().unwrap())
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_') { c } else { '_' })
            .collect::<String>();
        let path = images.join(format!("{name}.exr"));
        let test = read_exr(&path);
        assert_eq!(test.len(), reference.len());
        let mse = mse(&test, &reference);
        let rel = test
            .iter()
            .zip(&reference)
            .map(|(t, r)| ((t - r) as f64).powi(2) / ((*r as f64).powi(2) + 1e-2))
            .sum::<f64>()
            / test.len() as f64;
        assert!((mse.sqrt() - f(&p["error"]["rmse"])).abs() <= 1e-6 * mse.sqrt().max(1e-3), "{path:?} rmse");
        assert!((rel - f(&p["error"]["rel_mse"])).abs() <= 1e-6 * rel.max(1e-3), "{path:?} relmse");
        pairs.push((reference_file, path, f(&p["error"]["flip"])));
    }
    pairs
}

/// A CSV line split at commas outside double quotes ("" inside quotes is a quote).
fn split_csv(line: &str) -> Vec<String> {
    let (mut fields, mut cur, mut quoted, mut chars) =
        (Vec::new(), String::new(), false, line.chars().peekable());
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
    require!(vulkan());
    let (out, r) = sweep();
    let csv = std::fs::read_to_string(out.path().join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header = split_csv(lines.next().unwrap());
    let col =
        |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
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

#[test]
fn the_reference_is_cached_by_file_camera_size_and_samples() {
    let out = gpu_test!();
    let file = sky_scene().1.to_str().unwrap().to_string();
    let run = |spp: &str| {
        let o = bench(&[
            &file,
            "--size",
            "64x48",
            "--effects",
            "ao",
            "--techniques",
            "ao:none",
            "--reference-spp",
            spp,
            "--timing-frames",
            "1",
            "--warmup",
            "0",
            "--json",
            "--out",
            out.path().to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: Value = serde_json::from_slice(&o.stdout).unwrap();
        v["references"][0].clone()
    };
    let first = run("64");
    let again = run("64");
    let other = run("32");
    assert_eq!(
        (first["cached"].as_bool(), again["cached"].as_bool(), other["cached"].as_bool()),
        (Some(false), Some(true), Some(false))
    );
    assert_eq!(first["noise_floor"], again["noise_floor"], "the cached halves are the same images");
    assert_ne!(first["key"], other["key"]);
    assert_eq!(other["spp"], 32);
}

#[test]
fn the_page_of_a_sweep_shows_its_charts_in_a_browser() {
    let page = gpu_test!();
    let chromium = require!(chromium());
    // A copy of the sweep's page and charts, screenshotted with its SVG charts and without them:
    // the charts' part of the page must differ (they really load and draw).
    let (out, _) = sweep();
    for entry in std::fs::read_dir(out.path()).unwrap() {
        let path = entry.unwrap().path();
        if matches!(path.extension().and_then(|e| e.to_str()), Some("html" | "svg" | "png")) {
            std::fs::copy(&path, page.path().join(path.file_name().unwrap())).unwrap();
        }
    }
    let (html, profile) = (page.path().join("index.html"), page.path().join("profile"));
    let with = screenshot(&chromium, &html, &profile);
    assert_eq!(with.dimensions(), (1200, 1600));
    for chart in ["shadows.svg", "frame.svg"] {
        std::fs::remove_file(page.path().join(chart)).unwrap();
    }
    let without = screenshot(&chromium, &html, &profile);
    let differing = with.pixels().zip(without.pixels()).filter(|(a, b)| a != b).count();
    assert!(differing > 50_000, "only {differing} pixels differ with the charts removed");
    // The charts draw dark lines and text on white: plenty of non-white pixels where they are.
    let inked = with.pixels().filter(|p| p.0.iter().any(|&c| c < 128)).count();
    assert!(inked > 5_000, "{inked} dark pixels");
}
