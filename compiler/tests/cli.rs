//! The command line: demo, inspect, verify, plan, help and exit codes.

#[path = "util/run.rs"]
mod run;

use run::kiln;

/// `kiln inspect FILE | head -1`: the reader closes the pipe early. kiln stops quietly (exit 0,
/// nothing on stderr), as a C tool killed by SIGPIPE would, not with an "internal error".
#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    let dir = tempfile::tempdir().unwrap();
    kiln(dir.path(), &["demo", "-o", "demo.kiln"]).expect(0);
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(["inspect", "demo.kiln"])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Read nothing: close the pipe at once (the inspect output is longer than one write).
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "stderr: {stderr}");
    assert!(stderr.is_empty(), "stderr: {stderr}");
}

#[test]
fn demo_inspect_verify() {
    let dir = tempfile::tempdir().unwrap();
    let run = kiln(dir.path(), &["demo", "-o", "demo.kiln"]);
    run.expect(0);
    assert!(run.stdout.contains("wrote demo.kiln"), "{run:?}");
    let run = kiln(dir.path(), &["inspect", "demo.kiln", "--json"]);
    run.expect(0);
    let j: serde_json::Value = serde_json::from_str(&run.stdout).expect("inspect --json is JSON");
    let version = format!("{}.{}", kiln_format::header::VERSION_MAJOR, kiln_format::header::VERSION_MINOR);
    assert_eq!(j["format_version"], version.as_str());
    let kinds: Vec<&str> =
        j["sections"].as_array().unwrap().iter().map(|s| s["kind"].as_str().unwrap()).collect();
    assert_eq!(
        kinds,
        [
            "MANI", "MATL", "VERT", "TRIS", "TMAT", "CWBV", "SHDW", "PRBG", "PRBS", "PRBI", "PRBV", "VGRD",
            "VOXO", "VOXT", "LSLT", "LSBN", "LSRK", "LSCO", "LSCE", "LSPN"
        ]
    );
    assert_eq!(j["line_space"]["shaft_res"], 4);
    assert!(j["line_space"]["bytes_pnmt"].as_u64().unwrap() > 0);
    // FORMAT.md's PNMT: a front and a back record per filled shaft, 8 bytes each in the default
    // (compact) layout of a scene that samples no texture.
    let filled = j["line_space"]["filled_shafts"].as_u64().unwrap();
    assert_eq!(j["line_space"]["bytes_pnmt"].as_u64().unwrap(), 16 * filled);
    assert_eq!(j["line_space"]["pnmt_records"], "compact-no-uv");
    let text = kiln(dir.path(), &["inspect", "demo.kiln"]);
    assert!(text.stdout.contains("bytes per filled shaft: binary "), "{text:?}");
    assert!(text.stdout.contains(", PNMT 16.00"), "{text:?}");
    // FORMAT.md 1.3: compact records in VGRD and LSPN version 2; full ones (and their header) at
    // version 1, which a 1.2 reader reads.
    let version = |j: &serde_json::Value, kind: &str| {
        j["sections"].as_array().unwrap().iter().find(|s| s["kind"] == kind).unwrap()["version"].clone()
    };
    assert_eq!((version(&j, "VGRD"), version(&j, "LSPN")), (2.into(), 2.into()));
    kiln(dir.path(), &["demo", "-o", "full.kiln", "-q", "--pnmt-records", "full"]).expect(0);
    let full: serde_json::Value =
        serde_json::from_str(&kiln(dir.path(), &["inspect", "full.kiln", "--json"]).stdout).unwrap();
    assert_eq!((version(&full, "VGRD"), version(&full, "LSPN")), (1.into(), 1.into()));
    assert_eq!(full["line_space"]["pnmt_records"], "full");
    assert_eq!(full["line_space"]["bytes_pnmt"].as_u64().unwrap(), 32 * filled);
    kiln(dir.path(), &["verify", "full.kiln"]).expect(0);
    assert!(j["sections"].as_array().unwrap().iter().all(|s| s["checksum_ok"] == true));
    assert_eq!(j["summary"]["triangles"], 30);
    assert_eq!(j["manifest"]["lights"][0]["name"], "ceiling");
    let skipped: Vec<&str> =
        j["manifest"]["skipped"].as_array().unwrap().iter().map(|s| s["stage"].as_str().unwrap()).collect();
    assert_eq!(skipped, ["uvs", "vertex-colors", "textures", "brdf-lut", "media-visibility", "environment"]);
    let run = kiln(dir.path(), &["verify", "demo.kiln", "--rays", "20000", "--json"]);
    run.expect(0);
    let j: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(j["ok"], true);
    assert_eq!(j["bvh"]["mismatches"], 0);
    assert_eq!(j["bvh"]["rays"], 20000);
    assert!(j["bvh"]["hits"].as_u64().unwrap() > 15000);
    assert_eq!(j["candidates"]["mismatches"], 0);
    assert_eq!(j["binary"]["false_misses"], 0);
    assert!(j["binary"]["false_hits"].as_u64().is_some());
    for k in ["median", "p99", "max"] {
        assert!(j["pnmt"]["position_error"][k].as_f64().is_some());
        assert!(j["pnmt"]["normal_error_degrees"][k].as_f64().is_some());
    }
    assert!(j["pnmt"]["hit_disagreements"].as_u64().is_some());
    assert_eq!(j["line_space"]["rays"], 20000);
}

#[test]
fn verify_reports_what_and_where() {
    let dir = tempfile::tempdir().unwrap();
    kiln(dir.path(), &["demo", "-o", "d.kiln"]).expect(0);
    let path = dir.path().join("d.kiln");
    let j: serde_json::Value =
        serde_json::from_str(&kiln(dir.path(), &["inspect", "d.kiln", "--json"]).stdout).unwrap();
    let bvh = j["sections"].as_array().unwrap().iter().find(|s| s["kind"] == "CWBV").unwrap().clone();
    let mut bytes = std::fs::read(&path).unwrap();
    let at = bvh["offset"].as_u64().unwrap() as usize + 10;
    bytes[at] ^= 0x40;
    std::fs::write(&path, &bytes).unwrap();
    let run = kiln(dir.path(), &["verify", "d.kiln"]);
    run.expect(1).says("CWBV").says("checksum mismatch").says("offset 0x");
    assert_eq!(run.stderr.lines().count(), 1, "one line: {run:?}");
    let run = kiln(dir.path(), &["verify", "d.kiln", "--json"]);
    run.expect(1);
    let j: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(j["ok"], false);
    assert!(j["error"].as_str().unwrap().contains("checksum"));
}

#[test]
fn exit_codes() {
    let dir = tempfile::tempdir().unwrap();
    kiln(dir.path(), &["inspect", "missing.kiln"]).expect(4);
    kiln(dir.path(), &["inspect", "."]).expect(4).says("not a regular file");
    kiln(dir.path(), &["frobnicate"]).expect(2);
    kiln(dir.path(), &["compile"]).expect(2);
    kiln(dir.path(), &["compile", "x.obj", "--threads", "0"]).expect(2);
    kiln(dir.path(), &["plan", "x.obj", "--normals", "smooth:500"]).expect(2).says("crease angle '500'");
    kiln(dir.path(), &["plan", "x.obj", "--normals", "round"]).expect(2).says("flat, smooth or smooth:ANGLE");
    std::fs::write(dir.path().join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(dir.path().join("bad.toml"), "[bake]\nnormals = \"smooth:x\"\n").unwrap();
    kiln(dir.path(), &["plan", "t.obj", "-c", "bad.toml"]).expect(1).says("[bake] normals: crease angle 'x'");
    std::fs::write(dir.path().join("ok.toml"), "[bake]\nnormals = \"smooth:30\"\n").unwrap();
    kiln(dir.path(), &["plan", "t.obj", "-c", "ok.toml", "--normals", "flat"]).expect(0);
    std::fs::write(dir.path().join("scene.fbx"), b"x").unwrap();
    kiln(dir.path(), &["compile", "scene.fbx"]).expect(3).says("unsupported input format");
    std::fs::write(dir.path().join("notes.kiln"), b"hello\n").unwrap();
    kiln(dir.path(), &["verify", "notes.kiln"]).expect(1).says("looks like text");
    // Another major version: unsupported (3), naming both versions.
    kiln(dir.path(), &["demo", "-o", "d.kiln", "-q"]).expect(0);
    let mut b = std::fs::read(dir.path().join("d.kiln")).unwrap();
    b[8] = 9;
    std::fs::write(dir.path().join("d9.kiln"), &b).unwrap();
    let minor = u16::from_le_bytes([b[10], b[11]]);
    kiln(dir.path(), &["verify", "d9.kiln"]).expect(3).says(&format!("9.{minor}")).says("1.x");
}

#[test]
fn codec_option_and_sidecar_key() {
    // Which sections are compressed, as `kiln inspect --json` reports them: auto those whose
    // frame (its size in the zstd file) saves at least an eighth, and no other; zstd (command
    // line or sidecar) every section that shrinks, the sidecar overridden by the command line; a
    // bad value is a usage error naming the choices.
    let dir = tempfile::tempdir().unwrap();
    let sections = |file: &str| -> Vec<serde_json::Value> {
        let run = kiln(dir.path(), &["inspect", file, "--json"]);
        run.expect(0);
        let j: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
        j["sections"].as_array().unwrap().clone()
    };
    let codecs = |file: &str| -> Vec<(String, String)> {
        sections(file)
            .iter()
            .map(|s| (s["kind"].as_str().unwrap().to_string(), s["codec"].as_str().unwrap().to_string()))
            .collect()
    };
    kiln(dir.path(), &["demo", "-o", "auto.kiln", "-q"]).expect(0);
    kiln(dir.path(), &["demo", "-o", "all.kiln", "-q", "--codec", "zstd"]).expect(0);
    let (auto, all) = (sections("auto.kiln"), sections("all.kiln"));
    assert_eq!(auto.len(), all.len());
    let mut kept = 0;
    for (a, z) in auto.iter().zip(&all) {
        assert_eq!(a["kind"], z["kind"]);
        let (raw, frame) = (z["raw_size"].as_u64().unwrap(), z["size"].as_u64().unwrap());
        let expect = if frame * 8 <= raw * 7 { "zstd" } else { "none" };
        assert_eq!(a["codec"], expect, "{}: {frame} of {raw} bytes compressed", a["kind"]);
        kept += (expect == "zstd") as usize;
    }
    assert!(kept >= 10, "the demo's sections hardly compress: {kept}");
    kiln(dir.path(), &["demo", "-o", "none.kiln", "-q", "--codec", "none"]).expect(0);
    assert!(codecs("none.kiln").iter().all(|(_, c)| c == "none"));
    std::fs::write(dir.path().join("z.toml"), "[bake]\ncodec = \"zstd\"\n").unwrap();
    std::fs::write(dir.path().join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    kiln(dir.path(), &["demo", "-o", "z.kiln", "-q", "--codec", "zstd"]).expect(0);
    let z = codecs("z.kiln");
    assert!(z.iter().filter(|(_, c)| c == "zstd").count() >= 12, "{z:?}");
    kiln(dir.path(), &["compile", "t.obj", "-c", "z.toml", "-o", "t.kiln", "-q"]).expect(0);
    kiln(dir.path(), &["compile", "t.obj", "-c", "z.toml", "-o", "t0.kiln", "-q", "--codec", "none"])
        .expect(0);
    assert!(codecs("t0.kiln").iter().all(|(_, c)| c == "none"));
    let run = kiln(dir.path(), &["inspect", "t.kiln", "--json"]);
    let j: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let settings = j["manifest"]["settings"].as_array().unwrap();
    assert!(settings.iter().any(|s| s["key"] == "codec" && s["value"] == "zstd"), "{settings:?}");
    kiln(dir.path(), &["demo", "-o", "x.kiln", "--codec", "lz4"]).expect(2).says("auto, none or zstd");
    std::fs::write(dir.path().join("bad.toml"), "[bake]\ncodec = \"gzip\"\n").unwrap();
    kiln(dir.path(), &["plan", "t.obj", "-c", "bad.toml"]).expect(1).says("codec: 'gzip' is not a codec");
}

#[test]
fn shaft_variants_and_resolutions_are_honoured() {
    let dir = tempfile::tempdir().unwrap();
    kiln(
        dir.path(),
        &["demo", "-o", "b.kiln", "-q", "--shaft-variants", "binary", "--voxel-res", "3", "--shaft-res", "2"],
    )
    .expect(0);
    let j: serde_json::Value =
        serde_json::from_str(&kiln(dir.path(), &["inspect", "b.kiln", "--json"]).stdout).unwrap();
    assert_eq!(j["line_space"]["variants"], "binary");
    assert_eq!(j["line_space"]["shaft_res"], 2);
    assert_eq!(j["line_space"]["cells"][0], 3);
    assert_eq!(j["line_space"]["bytes_candidates"], 0);
    let run = kiln(dir.path(), &["verify", "b.kiln", "--rays", "5000", "--json"]);
    run.expect(0);
    let v: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(v["binary"]["false_misses"], 0);
    assert!(v["candidates"].is_null() && v["pnmt"].is_null());
    kiln(dir.path(), &["demo", "-o", "n.kiln", "-q", "--shaft-variants", "none"]).expect(0);
    let j: serde_json::Value =
        serde_json::from_str(&kiln(dir.path(), &["inspect", "n.kiln", "--json"]).stdout).unwrap();
    assert!(j["line_space"].is_null());
    // Every variant the help lists is accepted (`preillum` was listed but refused).
    kiln(
        dir.path(),
        &[
            "demo",
            "-o",
            "p.kiln",
            "-q",
            "--shaft-variants",
            "preillum",
            "--voxel-res",
            "3",
            "--shaft-res",
            "1",
        ],
    )
    .expect(0);
    let j: serde_json::Value =
        serde_json::from_str(&kiln(dir.path(), &["inspect", "p.kiln", "--json"]).stdout).unwrap();
    assert_eq!(j["line_space"]["variants"], "binary,preillum");
    kiln(dir.path(), &["demo", "-o", "x.kiln", "--shaft-variants", "fancy"])
        .expect(2)
        .says("unknown shaft variant");
    kiln(dir.path(), &["demo", "-o", "x.kiln", "--shaft-res", "9"]).expect(2);
    kiln(dir.path(), &["demo", "-o", "x.kiln", "--voxel-res", "huge"]).expect(2).says("neither 'auto'");
}

#[test]
fn help_explains_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let run = kiln(dir.path(), &["--help"]);
    for cmd in ["compile", "plan", "demo", "inspect", "verify", "cache", "Exit codes"] {
        assert!(run.stdout.contains(cmd), "--help lacks {cmd}");
    }
    let run = kiln(dir.path(), &["compile", "--help"]);
    for flag in [
        "--config",
        "--bvh-preset",
        "--report",
        "--depfile",
        "--threads",
        "--strict",
        "--cache",
        "--no-cache",
        "KILN_CACHE",
        "fast",
        "medium",
        "slow",
    ] {
        assert!(run.stdout.contains(flag), "compile --help lacks {flag}");
    }
    for (sub, flags) in [("stats", &["--json"][..]), ("gc", &["--max-size", "least recently used"][..])] {
        let run = kiln(dir.path(), &["cache", sub, "--help"]);
        for flag in flags.iter().chain(&["KILN_CACHE"]) {
            assert!(run.stdout.contains(flag), "cache {sub} --help lacks {flag}");
        }
    }
}

/// `kiln completions SHELL` and `kiln man` cover every subcommand and a nested flag; an
/// unknown shell is a usage error.
#[test]
fn completions_and_man_page_name_every_command() {
    let dir = tempfile::tempdir().unwrap();
    for shell in ["bash", "zsh", "fish"] {
        let run = kiln(dir.path(), &["completions", shell]);
        assert_eq!(run.code, 0, "{shell}: {}", run.stderr);
        for word in ["compile", "plan", "demo", "inspect", "verify", "cache", "max-size", "bvh-preset"] {
            assert!(run.stdout.contains(word), "{shell} completions lack {word}");
        }
    }
    let run = kiln(dir.path(), &["man"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stdout.starts_with(".ie") && run.stdout.contains(".TH kiln 1"), "not roff");
    for cmd in ["compile", "plan", "demo", "inspect", "verify", "cache"] {
        assert!(run.stdout.contains(&format!("kiln\\-{cmd}")), "man page lacks {cmd}");
    }
    assert_eq!(kiln(dir.path(), &["completions", "cmd.exe"]).code, 2);
}

#[test]
fn demo_is_deterministic_across_thread_counts() {
    let dir = tempfile::tempdir().unwrap();
    kiln(dir.path(), &["demo", "-o", "a.kiln", "--threads", "1", "-q"]).expect(0);
    kiln(dir.path(), &["demo", "-o", "b.kiln", "--threads", "2", "-q"]).expect(0);
    let a = std::fs::read(dir.path().join("a.kiln")).unwrap();
    let b = std::fs::read(dir.path().join("b.kiln")).unwrap();
    assert!(a == b, "demo output differs between 1 and 2 threads");
}

/// `--line-space-device`: the report says where the shafts were baked; `auto` keeps a demo's
/// small bake on the CPU (under `linespace::gpu::AUTO_MIN_WORK`); `gpu` without a GPU (CI's
/// machine: lavapipe is a CPU implementation, which only tests take) is an input error naming
/// the option, and with one the shafts are baked there and the file is the CPU's, byte for byte.
#[test]
fn line_space_device_is_reported_and_gpu_without_one_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["demo", "-q", "--shaft-variants", "binary,pnmt"];
    let with = |out: &str, device: &str| {
        let mut a = args.to_vec();
        a.extend(["-o", out, "--report"]);
        a.push(if out == "cpu.kiln" { "cpu.json" } else { "other.json" });
        a.extend(["--line-space-device", device]);
        kiln(dir.path(), &a)
    };
    with("cpu.kiln", "auto").expect(0);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("cpu.json")).unwrap()).unwrap();
    assert_eq!(report["line_space"]["device"], "cpu");
    let gpu = with("gpu.kiln", "gpu");
    if gpu.code == 0 {
        let other: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("other.json")).unwrap()).unwrap();
        assert_ne!(other["line_space"]["device"], "cpu");
        assert_eq!(
            std::fs::read(dir.path().join("gpu.kiln")).unwrap(),
            std::fs::read(dir.path().join("cpu.kiln")).unwrap()
        );
    } else {
        gpu.expect(3).says("--line-space-device gpu: no GPU");
    }
    kiln(dir.path(), &["demo", "-q", "--line-space-device", "tpu"]).expect(2);
}

#[test]
fn plan_names_the_emitter_table_with_its_total_power() {
    let dir = tempfile::tempdir().unwrap();
    // One emissive quad, 1 × 0.5 (two triangles), Ke 2 0.5 1, over a grey one: the power is
    // π · luminance · area = π · (0.2126·2 + 0.7152·0.5 + 0.0722·1) · 0.5.
    let mtl = "newmtl lamp\nKd 0 0 0\nKe 2 0.5 1\n\nnewmtl grey\nKd 0.5 0.5 0.5\n";
    let obj = "mtllib lamp.mtl\nv 0 1 0\nv 1 1 0\nv 1 1 0.5\nv 0 1 0.5\nv 0 0 0\nv 3 0 0\nv 0 0 3\n\
               usemtl lamp\nf 1 2 3\nf 1 3 4\nusemtl grey\nf 5 6 7\n";
    std::fs::write(dir.path().join("lamp.mtl"), mtl).unwrap();
    std::fs::write(dir.path().join("lamp.obj"), obj).unwrap();
    let power = std::f64::consts::PI * (0.2126 * 2.0 + 0.7152 * 0.5 + 0.0722 * 1.0) * 0.5;
    let plan = kiln(dir.path(), &["plan", "lamp.obj"]);
    let expected = format!("2 emissive triangles of 1 material, total power {power:.4}");
    assert!(plan.expect(0).stdout.contains(&expected), "{expected:?} not in {}", plan.stdout);
    std::fs::write(dir.path().join("dark.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let plan = kiln(dir.path(), &["plan", "dark.obj"]);
    assert!(plan.expect(0).stdout.contains("no emissive triangles"), "{}", plan.stdout);
}
