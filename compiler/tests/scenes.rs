//! The real scenes in ../shared/scenes: compile with the shipped sidecars, verify with 10⁵
//! rays, determinism across thread counts, depfile and report contents.

#[path = "util/run.rs"]
mod run;

use std::path::PathBuf;

use run::kiln;

/// The shared scenes folder, or `None` (the caller skips with a message).
fn shared_scene(name: &str) -> Option<PathBuf> {
    let p =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes").join(name).join("scene.gltf");
    if p.is_file() {
        Some(p)
    } else {
        eprintln!("skipped: {} is absent (the shared scenes live beside the checkout)", p.display());
        None
    }
}

/// The sidecar the tests ship for a shared scene.
fn sidecar(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/scenes").join(format!("{name}.toml"))
}

fn compile_scene(
    name: &str,
    dir: &std::path::Path,
    threads: &str,
    extra: &[&str],
) -> Option<std::path::PathBuf> {
    let input = shared_scene(name)?;
    let out = dir.join(format!("{name}-{threads}.kiln"));
    let side = sidecar(name);
    kiln(
        dir,
        &[
            "compile",
            input.to_str()?,
            "--config",
            side.to_str()?,
            "-o",
            out.to_str()?,
            "--threads",
            threads,
            "--report",
            &format!("{name}-{threads}.json"),
            "--depfile",
            &format!("{name}-{threads}.d"),
        ]
        .into_iter()
        .chain(extra.iter().copied())
        .collect::<Vec<_>>(),
    )
    .expect(0);
    Some(out)
}

/// Compiles `name` with 1 and 2 threads and checks the outputs, the report and the depfile;
/// returns the folder and the first output (`None`: the shared scenes are absent).
fn check_scene(
    name: &str,
    triangles: u64,
    textures: u64,
    extra: &[&str],
) -> Option<(tempfile::TempDir, PathBuf)> {
    let dir = tempfile::tempdir().unwrap();
    let one = compile_scene(name, dir.path(), "1", extra)?;
    let two = compile_scene(name, dir.path(), "2", extra).unwrap();
    assert!(
        std::fs::read(&one).unwrap() == std::fs::read(&two).unwrap(),
        "{name}: output differs between 1 and 2 threads"
    );

    let run = kiln(dir.path(), &["verify", one.to_str().unwrap(), "--rays", "100000", "--json"]);
    run.expect(0);
    let j: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(j["bvh"]["mismatches"], 0, "{name}: {}", j["bvh"]);
    assert_eq!(j["bvh"]["rays"], 100000);
    if !j["binary"].is_null() {
        assert_eq!(j["binary"]["false_misses"], 0, "{name}: {}", j["binary"]);
    }
    if !j["candidates"].is_null() {
        assert_eq!(j["candidates"]["mismatches"], 0, "{name}: {}", j["candidates"]);
    }

    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join(format!("{name}-1.json"))).unwrap()).unwrap();
    assert_eq!(report["counts"]["triangles"], triangles);
    assert_eq!(report["counts"]["textures"], textures);
    assert_eq!(report["threads"], 1);
    let stages: Vec<&str> =
        report["stages"].as_array().unwrap().iter().map(|s| s["stage"].as_str().unwrap()).collect();
    assert_eq!(
        stages,
        [
            "import",
            "geometry",
            "uvs",
            "vertex-colors",
            "materials",
            "textures",
            "bvh",
            "brdf-lut",
            "shadow-maps",
            "media-visibility",
            "environment",
            "probes",
            "voxel-grid",
            "line-space",
            "write"
        ]
    );
    for s in report["stages"].as_array().unwrap() {
        assert!(s["ms"].as_f64().unwrap() >= 0.0);
        assert!(!s["reason"].as_str().unwrap().is_empty());
        if s["run"] == false {
            assert_eq!(s["bytes"], 0);
        }
    }
    assert_eq!(report["bytes"], std::fs::metadata(&one).unwrap().len());

    let dep = std::fs::read_to_string(dir.path().join(format!("{name}-1.d"))).unwrap();
    let (target, deps) = dep.split_once(':').unwrap();
    assert_eq!(target, one.to_str().unwrap());
    let listed: Vec<&str> = deps.split_whitespace().filter(|w| *w != "\\").collect();
    let input = shared_scene(name).unwrap();
    let folder = input.parent().unwrap();
    assert!(listed.contains(&input.to_str().unwrap()), "{dep}");
    assert!(listed.contains(&sidecar(name).to_str().unwrap()), "{dep}");
    assert!(listed.contains(&folder.join("scene.bin").to_str().unwrap()), "{dep}");
    let pngs = listed.iter().filter(|p| p.ends_with(".png")).count() as u64;
    assert_eq!(pngs, textures, "{dep}");
    Some((dir, one))
}

#[test]
fn cornell_box() {
    // Every line-space variant (the plan's default for this lit scene).
    check_scene("cornell_box", 32, 0, &[]);
}

/// Bytes of `file`'s sections whose kind is in `kinds`, from `kiln inspect --json`.
fn section_bytes(dir: &std::path::Path, file: &std::path::Path, kinds: &[&str]) -> u64 {
    let run = kiln(dir, &["inspect", file.to_str().unwrap(), "--json"]);
    run.expect(0);
    let j: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    j["sections"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| kinds.contains(&s["kind"].as_str().unwrap()))
        .map(|s| s["raw_size"].as_u64().unwrap())
        .sum()
}

#[test]
fn pica_pica() {
    // The defaults: binary and PNMT within the default budget, twice the geometry's bytes, at
    // least 8 MiB (docs/linespace.md, "Voxel grid and line space"); summed from the written sections.
    let Some((dir, file)) = check_scene("pica_pica", 76_274, 6, &[]) else { return };
    let geometry = section_bytes(dir.path(), &file, &["VERT", "UVS0", "COL0", "TRIS", "TMAT"]);
    let budget = (2 * geometry).div_ceil(1 << 20).clamp(8, 384) << 20;
    let line_space = section_bytes(
        dir.path(),
        &file,
        &["VGRD", "VOXO", "VOXT", "LSLT", "LSBN", "LSRK", "LSCO", "LSCE", "LSPN", "LSPI"],
    );
    assert!(geometry > 3 << 20, "{geometry} bytes of geometry sections");
    assert!(line_space <= budget, "{line_space} bytes of line space over the {budget}-byte default budget");
    assert!(line_space > budget / 2, "{line_space} bytes: the {budget}-byte budget was not used");
    let pnmt = section_bytes(dir.path(), &file, &["LSPN"]);
    assert!(pnmt > 0, "the default drops PNMT only when binary + PNMT fits nowhere");
}

#[test]
fn pica_pica_every_line_space_variant() {
    let dir = tempfile::tempdir().unwrap();
    let Some(input) = shared_scene("pica_pica") else { return };
    let out = dir.path().join("p.kiln");
    kiln(
        dir.path(),
        &[
            "compile",
            input.to_str().unwrap(),
            "-c",
            sidecar("pica_pica").to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
            "--voxel-res",
            "12",
            "--shaft-res",
            "3",
            "--shaft-variants",
            "binary,candidates,pnmt",
        ],
    )
    .expect(0);
    let run = kiln(dir.path(), &["verify", out.to_str().unwrap(), "--rays", "20000", "--json"]);
    run.expect(0);
    let j: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(j["candidates"]["mismatches"], 0, "{}", j["candidates"]);
    assert_eq!(j["binary"]["false_misses"], 0, "{}", j["binary"]);
    assert!(j["pnmt"]["position_error"]["median"].as_f64().unwrap() < 2.0, "{}", j["pnmt"]);
}

#[test]
fn plan_names_every_stage() {
    let dir = tempfile::tempdir().unwrap();
    let Some(input) = shared_scene("cornell_box") else { return };
    let run = kiln(
        dir.path(),
        &["plan", input.to_str().unwrap(), "--json", "--config", sidecar("cornell_box").to_str().unwrap()],
    );
    run.expect(0);
    let j: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let stages = j["stages"].as_array().unwrap();
    let find = |n: &str| stages.iter().find(|s| s["stage"] == n).unwrap().clone();
    assert_eq!(find("textures")["run"], false);
    assert_eq!(find("textures")["reason"], "the scene has no textures");
    assert_eq!(find("uvs")["reason"], "no material samples a texture");
    assert_eq!(find("bvh")["run"], true);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "plan wrote files");
}
