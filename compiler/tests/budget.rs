//! `--line-space-budget`: the configuration it forces fits once baked (section bytes summed from
//! `kiln inspect --json`, independently of the estimator); too small a budget and resolutions
//! given over it are usage errors that say the smallest size; the estimate against the baked
//! size; `kiln demo --scene` writes the benchmark scenes.

#[path = "util/run.rs"]
mod run;

use std::path::Path;

use run::kiln;

/// Sections of the voxel grid and line space (FORMAT.md, "Voxel grid and line space").
const LINE_SPACE_KINDS: [&str; 10] =
    ["VGRD", "VOXO", "VOXT", "LSLT", "LSBN", "LSRK", "LSCO", "LSCE", "LSPN", "LSPI"];

fn inspect(dir: &Path, file: &str) -> serde_json::Value {
    let run = kiln(dir, &["inspect", file, "--json"]);
    run.expect(0);
    serde_json::from_str(&run.stdout).unwrap()
}

/// Bytes of the grid and line-space sections of `file`, from `kiln inspect --json`.
fn line_space_bytes(dir: &Path, file: &str) -> u64 {
    inspect(dir, file)["sections"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| LINE_SPACE_KINDS.contains(&s["kind"].as_str().unwrap()))
        .map(|s| s["raw_size"].as_u64().unwrap())
        .sum()
}

fn report(dir: &Path, file: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join(file)).unwrap()).unwrap()
}

#[test]
fn a_budget_forces_a_smaller_configuration_that_fits() {
    let dir = tempfile::tempdir().unwrap();
    // The default budget (its 8 MiB floor: the demo's geometry is tiny): 4 cells, N = 4, all
    // variants, 4.4 MiB.
    kiln(dir.path(), &["demo", "-o", "full.kiln", "-q", "--report", "full.json"]).expect(0);
    let full = line_space_bytes(dir.path(), "full.kiln");
    let r = report(dir.path(), "full.json");
    assert_eq!(r["line_space_plan"]["estimate"]["shaft_res"], 4);
    assert_eq!(r["line_space"]["variants"], "binary,candidates,pnmt");
    assert_eq!(r["line_space"]["pnmt_records"], "compact-no-uv");
    // Every cell of the demo is sampled, so the estimate is the baked size.
    assert_eq!(r["line_space_plan"]["bytes"].as_u64().unwrap(), full);
    // 1 MiB: the voxel resolution is at its floor (4), so N drops; candidates go first (binary
    // + PNMT at N = 4 takes 2.6 MiB with the default 8-byte records, at N = 3 0.9 MiB).
    kiln(dir.path(), &["demo", "-o", "b.kiln", "-q", "--line-space-budget", "1", "--report", "b.json"])
        .expect(0);
    let bytes = line_space_bytes(dir.path(), "b.kiln");
    assert!(bytes <= 1 << 20, "{bytes} bytes of line space over the 1 MiB budget");
    assert!(bytes > 1 << 19, "{bytes} bytes: the budget was not used (N lowered too far)");
    let j = inspect(dir.path(), "b.kiln");
    assert_eq!(j["line_space"]["shaft_res"], 3);
    assert_eq!(j["line_space"]["variants"], "binary,pnmt");
    assert_eq!(report(dir.path(), "b.json")["line_space_bytes"].as_u64().unwrap(), bytes);
    // The plan says the same without writing.
    let plan = kiln(dir.path(), &["plan", "--help"]);
    assert!(plan.stdout.contains("--line-space-budget"));
}

#[test]
fn a_budget_lowers_the_voxel_resolution_first() {
    let dir = tempfile::tempdir().unwrap();
    // The teapot-count box: auto resolution 25; 24 MiB forces a coarser grid at N = 4.
    kiln(
        dir.path(),
        &[
            "demo",
            "--scene",
            "box-teapot",
            "-o",
            "t.kiln",
            "-q",
            "--line-space-budget",
            "24",
            "--report",
            "t.json",
        ],
    )
    .expect(0);
    let bytes = line_space_bytes(dir.path(), "t.kiln");
    assert!(bytes <= 24 << 20, "{bytes} bytes of line space over the 24 MiB budget");
    let j = inspect(dir.path(), "t.kiln");
    assert_eq!(j["line_space"]["shaft_res"], 4);
    let cells = j["line_space"]["cells"].as_array().unwrap().iter().map(|c| c.as_u64().unwrap()).max();
    assert!(cells.unwrap() < 25 && cells.unwrap() >= 4, "{cells:?}");
    // The estimate (an upper bound at two standard errors of a 256-cell sample) is within 10%.
    let r = report(dir.path(), "t.json");
    let estimate = r["line_space_plan"]["bytes"].as_u64().unwrap() as f64;
    let ratio = estimate / bytes as f64;
    assert!((0.97..=1.10).contains(&ratio), "estimate {estimate} vs {bytes} baked: {ratio:.3}");
}

#[test]
fn too_small_a_budget_says_the_smallest_size() {
    let dir = tempfile::tempdir().unwrap();
    // 200 cells given: the grid alone (cell offsets, slots) needs tens of MiB at any N.
    kiln(dir.path(), &["demo", "-o", "x.kiln", "--voxel-res", "200", "--line-space-budget", "1"])
        .expect(2)
        .says("fits no 1 MiB --line-space-budget")
        .says("the smallest configuration (200 cells, N = 1, binary) needs about")
        .says("--shaft-variants none");
    assert!(!dir.path().join("x.kiln").exists());
    kiln(dir.path(), &["plan", "x.obj", "--line-space-budget", "0"]).expect(2);
}

#[test]
fn resolutions_given_over_the_budget_are_an_error_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    // Both given: not searched. PNMT at 8 cells and N = 4 needs about 15 MiB.
    kiln(
        dir.path(),
        &[
            "demo",
            "-o",
            "x.kiln",
            "--voxel-res",
            "8",
            "--shaft-res",
            "4",
            "--shaft-variants",
            "pnmt",
            "--line-space-budget",
            "2",
        ],
    )
    .expect(2)
    .says("--voxel-res 8 and --shaft-res 4 need about")
    .says("over the 2 MiB --line-space-budget");
    // One given: the other is searched (N here) and the given one kept.
    kiln(
        dir.path(),
        &[
            "demo",
            "-o",
            "v.kiln",
            "-q",
            "--voxel-res",
            "8",
            "--shaft-variants",
            "pnmt",
            "--line-space-budget",
            "2",
        ],
    )
    .expect(0);
    let j = inspect(dir.path(), "v.kiln");
    assert_eq!(j["line_space"]["cells"][0], 8);
    assert!(j["line_space"]["shaft_res"].as_u64().unwrap() < 4);
    assert_eq!(j["line_space"]["variants"], "binary,pnmt");
    assert!(line_space_bytes(dir.path(), "v.kiln") <= 2 << 20);
    // Explicit variants without a budget: as requested, unbudgeted (as before budgets).
    kiln(dir.path(), &["demo", "-o", "u.kiln", "-q", "--voxel-res", "8", "--shaft-variants", "pnmt"])
        .expect(0);
    assert!(line_space_bytes(dir.path(), "u.kiln") > 2 << 20);
}

#[test]
fn demo_writes_the_benchmark_scenes() {
    let dir = tempfile::tempdir().unwrap();
    // No line space: the test needs the triangles, not the bake.
    kiln(dir.path(), &["demo", "--scene", "box-bunny", "-o", "b.kiln", "-q", "--shaft-variants", "none"])
        .expect(0);
    let j = inspect(dir.path(), "b.kiln");
    assert_eq!(j["summary"]["triangles"], 69_451 + 12, "{:#}", j["summary"]);
    assert_eq!(j["manifest"]["cameras"].as_array().unwrap().len(), 1);
    kiln(dir.path(), &["demo", "--scene", "cornell", "-o", "c.kiln", "-q", "--shaft-variants", "none"])
        .expect(0);
    assert_eq!(inspect(dir.path(), "c.kiln")["summary"]["triangles"], 32);
    let help = kiln(dir.path(), &["demo", "--help"]);
    for scene in ["box-teapot", "box-bunny", "box-dragon", "871,306"] {
        assert!(help.stdout.contains(scene), "demo --help lacks {scene}");
    }
}
