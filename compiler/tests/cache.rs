//! The stage cache (`--cache DIR`, `KILN_CACHE`, `kiln cache stats|gc`): every compile through a
//! cache is checked byte for byte against the same compile without one, and the report's
//! `cached` flags against which stages read what changed.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `kiln` in `dir` with a clean environment for the cache: no `KILN_CACHE` unless given, and
/// HOME and XDG_CACHE_HOME pointed into `dir/home` (so that state written there would show).
fn kiln_env(dir: &Path, args: &[&str], env_cache: Option<&str>) -> Output {
    let home = dir.join("home");
    std::fs::create_dir_all(&home).unwrap();
    let mut c = Command::new(env!("CARGO_BIN_EXE_kiln"));
    c.args(args).current_dir(dir).env_remove("KILN_CACHE").env("HOME", &home).env("XDG_CACHE_HOME", &home);
    if let Some(v) = env_cache {
        c.env("KILN_CACHE", v);
    }
    c.output().expect("kiln runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Runs `kiln` and asserts success and no panic; returns stderr.
fn ok(dir: &Path, args: &[&str]) -> String {
    let out = kiln_env(dir, args, None);
    assert!(
        out.status.success(),
        "kiln {args:?} failed ({:?})\n--- stdout:\n{}\n--- stderr:\n{}",
        out.status.code(),
        text(&out.stdout),
        text(&out.stderr)
    );
    text(&out.stderr)
}

/// A sidecar adding a shadow-casting point light at `pos` to the demo box (which has its own
/// ceiling light) and a specular lobe to its red wall (so that the BRDF table is baked).
fn sidecar(dir: &Path, name: &str, pos: [f32; 3]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!(
            "[material.\"red\"]\ndiffuse_only = false\nroughness = 0.4\n\n[[light]]\nkind = \"point\"\nname = \"bulb\"\nposition = [{}, {}, {}]\ncolor = [1.0, 1.0, 1.0]\nintensity = 2.0\n",
            pos[0], pos[1], pos[2]
        ),
    )
    .unwrap();
    p
}

/// Compiles the demo box with `args` into `out`, through `cache` if given; returns the report's
/// `cached` flag of every stage that ran (import and write aside) and the stderr.
fn demo(dir: &Path, out: &str, cache: Option<&str>, args: &[&str]) -> (Vec<(String, bool)>, String) {
    let report = format!("{out}.json");
    let mut all = vec!["demo", "-o", out, "--report", &report, "--threads", "2", "-q"];
    // Light bakes (what is cached matters here, not its quality): 16 paths per probe instead of
    // 256, 64-texel shadow maps instead of 1024, unless the test sets them itself.
    for (flag, value) in [("--probe-rays", "16"), ("--shadow-res", "64")] {
        if !args.contains(&flag) {
            all.extend_from_slice(&[flag, value]);
        }
    }
    all.extend_from_slice(args);
    if let Some(c) = cache {
        all.extend_from_slice(&["--cache", c]);
    }
    let stderr = ok(dir, &all);
    (stages(&dir.join(&report)), stderr)
}

/// The `cached` flag of every stage that ran (import and write aside) in the `--report` at `path`.
fn stages(path: &Path) -> Vec<(String, bool)> {
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    j["stages"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s["run"] == true && !matches!(s["stage"].as_str(), Some("import" | "write")))
        .map(|s| (s["stage"].as_str().unwrap().to_string(), s["cached"].as_bool().unwrap()))
        .collect()
}

/// The stages with `cached == want`.
fn with(stages: &[(String, bool)], want: bool) -> Vec<&str> {
    stages.iter().filter(|s| s.1 == want).map(|s| s.0.as_str()).collect()
}

/// Asserts that two files are byte-identical (and says where they differ).
fn same(dir: &Path, a: &str, b: &str) {
    let (x, y) = (std::fs::read(dir.join(a)).unwrap(), std::fs::read(dir.join(b)).unwrap());
    let first = x.iter().zip(&y).position(|(p, q)| p != q);
    assert!(x == y, "{a} ({} B) and {b} ({} B) differ, first at byte {first:?}", x.len(), y.len());
}

/// Entry files under a cache directory (stage/key.kiln), by stage.
fn entries(cache: &Path) -> Vec<(String, PathBuf, u64)> {
    let mut v = Vec::new();
    for stage in std::fs::read_dir(cache).unwrap().flatten() {
        if !stage.path().is_dir() || stage.file_name() == "tmp" {
            continue;
        }
        for e in std::fs::read_dir(stage.path()).unwrap().flatten() {
            v.push((stage.file_name().to_string_lossy().into_owned(), e.path(), e.metadata().unwrap().len()));
        }
    }
    v.sort();
    v
}

#[test]
fn a_warm_cache_reuses_every_stage_and_writes_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let side = sidecar(d, "a.toml", [0.2, 1.2, 0.1]);
    let side = side.to_str().unwrap();
    demo(d, "plain.kiln", None, &["-c", side]);
    let (cold, _) = demo(d, "cold.kiln", Some("c"), &["-c", side]);
    let (warm, stderr) = demo(d, "warm.kiln", Some("c"), &["-c", side]);
    assert_eq!(with(&cold, true), Vec::<&str>::new(), "an empty cache holds nothing");
    assert_eq!(with(&warm, false), Vec::<&str>::new(), "every stage is reused: {warm:?}");
    assert_eq!(
        warm.len(),
        8,
        "geometry, materials, bvh, brdf-lut, shadow-maps, probes, voxel-grid, line-space: {warm:?}"
    );
    assert!(!stderr.contains("warning"), "{stderr}");
    same(d, "plain.kiln", "cold.kiln");
    same(d, "plain.kiln", "warm.kiln");
    // KILN_CACHE names the same cache; --no-cache turns it off.
    let light = ["--probe-rays", "16", "--shadow-res", "64"];
    let out = kiln_env(
        d,
        &[&["demo", "-o", "env.kiln", "-c", side, "--report", "env.json", "-q"][..], &light].concat(),
        Some("c"),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("env.json")).unwrap()).unwrap();
    assert!(
        j["stages"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|s| s["stage"] == "line-space")
            .all(|s| s["cached"] == true)
    );
    same(d, "plain.kiln", "env.kiln");
    let out = kiln_env(
        d,
        &[&["demo", "-o", "off.kiln", "-c", side, "--no-cache", "--report", "off.json", "-q"][..], &light]
            .concat(),
        Some("c"),
    );
    assert!(out.status.success());
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("off.json")).unwrap()).unwrap();
    assert!(j["cache"].is_null() && j["stages"].as_array().unwrap().iter().all(|s| s["cached"] == false));
}

#[test]
fn without_a_cache_nothing_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let before: Vec<_> = std::fs::read_dir(d).unwrap().flatten().map(|e| e.file_name()).collect();
    demo(d, "x.kiln", None, &[]);
    let mut after: Vec<_> = std::fs::read_dir(d).unwrap().flatten().map(|e| e.file_name()).collect();
    after.sort();
    assert!(before.is_empty());
    assert_eq!(after, ["home", "x.kiln", "x.kiln.json"], "only the output and its report");
    assert_eq!(std::fs::read_dir(d.join("home")).unwrap().count(), 0, "nothing in the home directory");
}

#[test]
fn a_light_change_rebakes_the_shadow_maps_and_reuses_geometry_bvh_and_line_space() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = sidecar(d, "a.toml", [0.2, 1.2, 0.1]);
    let b = sidecar(d, "b.toml", [-0.3, 0.8, 0.4]);
    demo(d, "a.kiln", Some("c"), &["-c", a.to_str().unwrap()]);
    let (stages, _) = demo(d, "b.kiln", Some("c"), &["-c", b.to_str().unwrap()]);
    demo(d, "b-plain.kiln", None, &["-c", b.to_str().unwrap()]);
    same(d, "b-plain.kiln", "b.kiln");
    // The probes are lit by the lights too.
    assert_eq!(with(&stages, false), ["shadow-maps", "probes"], "{stages:?}");
    for s in ["geometry", "materials", "bvh", "brdf-lut", "voxel-grid", "line-space"] {
        assert!(with(&stages, true).contains(&s), "{s} not reused: {stages:?}");
    }
}

#[test]
fn the_pre_illuminated_line_space_depends_on_the_lights() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = sidecar(d, "a.toml", [0.2, 1.2, 0.1]);
    let b = sidecar(d, "b.toml", [-0.3, 0.8, 0.4]);
    let v = ["--shaft-variants", "binary,preillum", "--shaft-res", "2"];
    let args = |side: &Path| -> Vec<String> {
        let mut x = vec!["-c".to_string(), side.display().to_string()];
        x.extend(v.iter().map(|s| s.to_string()));
        x
    };
    let (a_args, b_args) = (args(&a), args(&b));
    let a_args: Vec<&str> = a_args.iter().map(String::as_str).collect();
    let b_args: Vec<&str> = b_args.iter().map(String::as_str).collect();
    demo(d, "a.kiln", Some("c"), &a_args);
    let (stages, _) = demo(d, "b.kiln", Some("c"), &b_args);
    demo(d, "b-plain.kiln", None, &b_args);
    same(d, "b-plain.kiln", "b.kiln");
    assert_eq!(with(&stages, false), ["shadow-maps", "probes", "voxel-grid", "line-space"], "{stages:?}");
    assert!(with(&stages, true).contains(&"bvh"), "{stages:?}");
}

#[test]
fn a_setting_change_misses_exactly_the_stages_that_read_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let side = sidecar(d, "a.toml", [0.2, 1.2, 0.1]);
    let side = side.to_str().unwrap();
    demo(d, "base.kiln", Some("c"), &["-c", side]);
    let cases: [(&[&str], &[&str]); 6] = [
        (&["--shadow-res", "128"], &["shadow-maps"]),
        (&["--probe-rays", "64"], &["probes"]),
        (&["--probe-regularize", "0.25"], &["probes"]),
        (&["--brdf-lut-res", "32"], &["brdf-lut", "probes"]),
        (&["--shaft-res", "3"], &["voxel-grid", "line-space"]),
        // Everything stored in BVH order, and everything that traces rays through it.
        (
            &["--bvh-preset", "fast"],
            &["geometry", "bvh", "shadow-maps", "probes", "voxel-grid", "line-space"],
        ),
    ];
    for (i, (args, missed)) in cases.iter().enumerate() {
        let args = &[&["-c", side][..], args].concat();
        let (stages, _) = demo(d, &format!("{i}.kiln"), Some("c"), args);
        demo(d, &format!("{i}-plain.kiln"), None, args);
        same(d, &format!("{i}-plain.kiln"), &format!("{i}.kiln"));
        assert_eq!(with(&stages, false), *missed, "{args:?}: {stages:?}");
    }
}

#[test]
fn a_damaged_entry_is_a_warning_and_a_rebake() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    demo(d, "plain.kiln", None, &[]);
    demo(d, "cold.kiln", Some("c"), &[]);
    let all = entries(&d.join("c"));
    let find = |stage: &str| all.iter().find(|e| e.0 == stage).unwrap().1.clone();
    // One byte flipped in the middle of the line space, and the shadow maps cut short.
    let ls = find("line-space");
    let mut bytes = std::fs::read(&ls).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x40;
    std::fs::write(&ls, bytes).unwrap();
    let sm = find("shadow-maps");
    let len = std::fs::metadata(&sm).unwrap().len();
    std::fs::OpenOptions::new().write(true).open(&sm).unwrap().set_len(len / 3).unwrap();
    let (stages, stderr) = demo(d, "warm.kiln", Some("c"), &[]);
    same(d, "plain.kiln", "warm.kiln");
    assert_eq!(with(&stages, false), ["shadow-maps", "voxel-grid", "line-space"], "{stages:?}");
    for e in [&ls, &sm] {
        let name = e.file_name().unwrap().to_str().unwrap();
        assert!(
            stderr.lines().any(|l| l.starts_with("warning: stage cache") && l.contains(name)),
            "no warning names {name}: {stderr}"
        );
    }
    // The re-bake replaced the damaged entries.
    let (stages, stderr) = demo(d, "again.kiln", Some("c"), &[]);
    assert_eq!(with(&stages, false), Vec::<&str>::new(), "{stages:?}");
    assert!(stderr.is_empty(), "{stderr}");
    same(d, "plain.kiln", "again.kiln");
}

#[test]
fn concurrent_compiles_into_one_cache_agree() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    demo(d, "plain.kiln", None, &[]);
    let runs: Vec<_> = (0..4)
        .map(|i| {
            let mut c = Command::new(env!("CARGO_BIN_EXE_kiln"));
            c.args(["demo", "-o", &format!("{i}.kiln"), "--threads", "1", "-q", "--cache", "c"])
                .args(["--probe-rays", "16", "--shadow-res", "64"])
                .current_dir(d)
                .env_remove("KILN_CACHE")
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped());
            c.spawn().unwrap()
        })
        .collect();
    for (i, r) in runs.into_iter().enumerate() {
        let out = r.wait_with_output().unwrap();
        assert!(out.status.success(), "compile {i} failed: {}", text(&out.stderr));
        assert!(out.stderr.is_empty(), "compile {i}: {}", text(&out.stderr));
        same(d, "plain.kiln", &format!("{i}.kiln"));
    }
    // Then one more that reads what they wrote.
    let (stages, stderr) = demo(d, "after.kiln", Some("c"), &[]);
    assert!(stderr.is_empty(), "{stderr}");
    assert_eq!(with(&stages, false), Vec::<&str>::new());
    same(d, "plain.kiln", "after.kiln");
    let stages: Vec<String> = entries(&d.join("c")).into_iter().map(|e| e.0).collect();
    let mut unique = stages.clone();
    unique.dedup();
    assert_eq!(stages, unique, "one entry per stage");
    assert_eq!(std::fs::read_dir(d.join("c/tmp")).unwrap().count(), 0, "no temporary file left");
}

/// Sets a file's modification time to `secs` after the epoch.
fn touch(p: &Path, secs: u64) {
    let t = std::time::UNIX_EPOCH + std::time::Duration::from_secs(secs);
    std::fs::File::options().append(true).open(p).unwrap().set_modified(t).unwrap();
}

#[test]
fn stats_count_entries_and_gc_evicts_the_least_recently_used_down_to_the_size() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    demo(d, "a.kiln", Some("c"), &[]);
    demo(d, "b.kiln", Some("c"), &["--shadow-res", "128", "--shaft-res", "3"]);
    let c = d.join("c");
    let all = entries(&c);
    let total: u64 = all.iter().map(|e| e.2).sum();
    let out = kiln_env(d, &["cache", "stats", "c", "--json"], None);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["entries"], all.len());
    assert_eq!(j["bytes"], total);
    let shadow: Vec<_> = all.iter().filter(|e| e.0 == "shadow-maps").collect();
    let row = j["stages"].as_array().unwrap().iter().find(|s| s["stage"] == "shadow-maps").unwrap().clone();
    assert_eq!(row["entries"], 2);
    assert_eq!(row["bytes"], shadow.iter().map(|e| e.2).sum::<u64>());
    // Ages: entry k was last used at time 1000 + k; keep the newest that fit in half the total.
    for (k, e) in all.iter().enumerate() {
        touch(&e.1, 1000 + k as u64);
    }
    let limit = total / 2;
    let mut expect_kept = Vec::new();
    let mut kept_bytes = 0;
    for e in all.iter().rev() {
        if kept_bytes + e.2 > limit {
            break;
        }
        kept_bytes += e.2;
        expect_kept.push(e.1.clone());
    }
    expect_kept.sort();
    let out = kiln_env(d, &["cache", "gc", "--max-size", &limit.to_string()], Some(c.to_str().unwrap()));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let mut kept: Vec<PathBuf> = entries(&c).into_iter().map(|e| e.1).collect();
    kept.sort();
    assert_eq!(kept, expect_kept, "gc kept other entries than the newest that fit");
    assert!(kept_bytes <= limit);
    // A compile after gc re-bakes what was evicted and still writes the same bytes.
    demo(d, "again.kiln", Some("c"), &[]);
    same(d, "a.kiln", "again.kiln");
    let out = kiln_env(d, &["cache", "gc", "--max-size", "0", "c"], None);
    assert!(out.status.success());
    assert!(entries(&c).is_empty());
}

#[test]
fn a_cache_that_cannot_be_written_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("file"), b"x").unwrap();
    for bad in ["file", "file/sub"] {
        let out = kiln_env(d, &["demo", "-o", "x.kiln", "--cache", bad], None);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(4), "{stderr}");
        assert!(stderr.starts_with("error: cache directory ") && stderr.contains(bad), "{stderr}");
        assert!(!d.join("x.kiln").exists(), "nothing written");
    }
    let out = kiln_env(d, &["cache", "stats"], None);
    assert_eq!(out.status.code(), Some(2), "no directory given nor KILN_CACHE: {}", text(&out.stderr));
    assert!(text(&out.stderr).contains("KILN_CACHE"));
    let out = kiln_env(d, &["cache", "gc", "--max-size", "12Q", "c"], None);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn concurrent_stores_and_loads_of_one_key_never_see_a_partial_entry() {
    use kiln_compiler::cache::Cache;
    use kiln_format::{ContentHash, SectionKind};
    let dir = tempfile::tempdir().unwrap();
    let cache = Cache::open(&dir.path().join("c")).unwrap();
    let key = ContentHash::of(b"one key");
    // 4 MiB, so that a write takes long enough for the others to overlap it.
    let payload: Vec<u8> = (0..4u32 << 20).map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8).collect();
    let kind = SectionKind(*b"kTST");
    std::thread::scope(|s| {
        for t in 0..6 {
            let (cache, payload) = (&cache, &payload);
            s.spawn(move || {
                for i in 0..12 {
                    if (t + i) % 2 == 0 {
                        cache.store("test", &key, &Default::default(), &[(kind, 0, payload)]).unwrap();
                    } else {
                        match cache.load("test", &key) {
                            Ok(None) => {}
                            Ok(Some(e)) => {
                                assert!(e.sections[0].bytes == *payload, "a load returned other bytes")
                            }
                            Err(e) => panic!("a load saw a damaged entry: {e}"),
                        }
                    }
                }
            });
        }
    });
    let e = cache.load("test", &key).unwrap().expect("stored");
    assert!(e.sections[0].bytes == payload);
    assert_eq!(std::fs::read_dir(dir.path().join("c/tmp")).unwrap().count(), 0, "no temporary file left");
}

#[test]
fn a_material_change_misses_only_the_material_table() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = sidecar(d, "a.toml", [0.2, 1.2, 0.1]);
    demo(d, "a.kiln", Some("c"), &["-c", a.to_str().unwrap()]);
    // The same light, the red wall rougher: PNMT records hold material numbers, not parameters,
    // and shadows ignore materials; the probes' light bounces off it.
    let b = d.join("b.toml");
    std::fs::write(&b, std::fs::read_to_string(&a).unwrap().replace("roughness = 0.4", "roughness = 0.7"))
        .unwrap();
    let (stages, _) = demo(d, "b.kiln", Some("c"), &["-c", b.to_str().unwrap()]);
    demo(d, "b-plain.kiln", None, &["-c", b.to_str().unwrap()]);
    same(d, "b-plain.kiln", "b.kiln");
    assert_eq!(with(&stages, false), ["materials", "probes"], "{stages:?}");
}

#[test]
fn a_light_colour_change_rebakes_no_shadow_map() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = sidecar(d, "a.toml", [0.2, 1.2, 0.1]);
    demo(d, "a.kiln", Some("c"), &["-c", a.to_str().unwrap()]);
    let b = d.join("b.toml");
    let text = std::fs::read_to_string(&a).unwrap();
    std::fs::write(
        &b,
        text.replace("color = [1.0, 1.0, 1.0]\nintensity = 2.0", "color = [1.0, 0.5, 0.2]\nintensity = 7.0"),
    )
    .unwrap();
    let (stages, _) = demo(d, "b.kiln", Some("c"), &["-c", b.to_str().unwrap()]);
    demo(d, "b-plain.kiln", None, &["-c", b.to_str().unwrap()]);
    same(d, "b-plain.kiln", "b.kiln");
    assert_ne!(
        std::fs::read(d.join("a.kiln")).unwrap(),
        std::fs::read(d.join("b.kiln")).unwrap(),
        "the light changed"
    );
    // Only the probes hold the light's colour.
    assert_eq!(with(&stages, false), ["probes"], "{stages:?}");
}

#[test]
fn an_environment_change_misses_the_environment_and_the_probes_only() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let env = ["--environment", "studio", "--environment-res", "64", "--shaft-res", "1"];
    let (first, _) = demo(d, "a.kiln", Some("c"), &env);
    assert!(first.iter().any(|s| s.0 == "environment"), "{first:?}");
    // The same environment again: every stage from the cache, the same bytes.
    let (warm, _) = demo(d, "b.kiln", Some("c"), &env);
    assert_eq!(with(&warm, false), Vec::<&str>::new(), "{warm:?}");
    same(d, "a.kiln", "b.kiln");
    // Turned: the map changes, and the probes that see it; nothing else reads it.
    let turned = [&env[..], &["--environment-rotation", "90"]].concat();
    let (stages, _) = demo(d, "c.kiln", Some("c"), &turned);
    demo(d, "c-plain.kiln", None, &turned);
    same(d, "c-plain.kiln", "c.kiln");
    assert_eq!(with(&stages, false), ["environment", "probes"], "{stages:?}");
    // A finer map: the same.
    let finer = ["--environment", "studio", "--environment-res", "128", "--shaft-res", "1"];
    let (stages, _) = demo(d, "d.kiln", Some("c"), &finer);
    assert_eq!(with(&stages, false), ["environment", "probes"], "{stages:?}");
}

/// One cache shared by two checkouts in different folders (a directory on shared storage, or a
/// CI cache restored elsewhere): the second compile of the same files takes every stage from it
/// and writes the first's bytes (issue 46, part 4). Keys hold contents, never paths.
#[test]
fn a_cache_filled_from_one_checkout_serves_another_elsewhere() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = |at: &Path| {
        std::fs::create_dir_all(at).unwrap();
        std::fs::write(
            at.join("s.obj"),
            "mtllib s.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl lamp\nf 1 2 3\nusemtl red\nf 1 2 4\nf 1 3 4\n",
        )
        .unwrap();
        std::fs::write(at.join("s.mtl"), "newmtl lamp\nKe 4 4 4\nnewmtl red\nKd 0.5 0.1 0.1\n").unwrap();
        sidecar(at, "s.toml", [0.3, 0.3, 1.0]);
    };
    let (a, b) = (d.join("a"), d.join("b/other/checkout"));
    scene(&a);
    scene(&b);
    let cache = d.join("shared-cache");
    let compile = |at: &Path, out: &str| {
        let report = d.join(format!("{out}.json"));
        ok(
            at,
            &[
                "compile",
                "s.obj",
                "-c",
                "s.toml",
                "-o",
                &d.join(out).display().to_string(),
                "--report",
                &report.display().to_string(),
                "--cache",
                &cache.display().to_string(),
                "-q",
                "-W",
                "missing-setup=ignore",
            ],
        );
        stages(&report)
    };
    let first = compile(&a, "a.kiln");
    assert!(with(&first, true).is_empty() && !first.is_empty(), "a cold cache: {first:?}");
    let second = compile(&b, "b.kiln");
    assert_eq!(with(&second, false), Vec::<&str>::new(), "every stage from the cache: {second:?}");
    same(d, "a.kiln", "b.kiln");
}
