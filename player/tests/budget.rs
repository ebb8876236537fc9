//! `kiln-play --budget-ms` as a user runs it, on a results file written here (the committed
//! McGuire-box results with their frame points replaced by a known set): the choice is the
//! lowest-error point whose frame time (per frame, not per image) fits, found here by brute
//! force; nothing fitting is refused with exit 2, naming the cheapest point's time. The choice
//! is made before the file is read, so no GPU is needed (the file does not exist: exit 4 after
//! the choice).

use std::process::Command;

use serde_json::{Value, json};

/// (technique, frames, frame ms, FLIP): a point at 4 frames whose image (4 × its frame) is over
/// the budgets below while its frame fits.
const POINTS: [(&str, u32, f64, f64); 5] = [
    ("visibility/baked", 1, 1.0, 0.30),
    ("visibility/hybrid", 1, 1.5, 0.28),
    ("raster/rt-taa", 4, 2.0, 0.20),
    ("raster/rt-taa", 16, 2.0, 0.10),
    ("visibility/rt-4", 1, 6.0, 0.15),
];

fn results_file(dir: &std::path::Path) -> std::path::PathBuf {
    let committed = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/benchmarks/denoise/box-results.json");
    let mut r: Value = serde_json::from_str(&std::fs::read_to_string(committed).unwrap()).unwrap();
    let template = r["points"].as_array().unwrap().iter().find(|p| p["effect"] == "frame").unwrap().clone();
    let points: Vec<Value> = POINTS
        .iter()
        .map(|&(technique, frames, ms, flip)| {
            let mut p = template.clone();
            p["technique"] = json!(technique);
            p["frames"] = json!(frames);
            p["frame_ms"] = json!(ms);
            p["image_ms"] = json!(ms * frames as f64);
            p["error"]["flip"] = json!(flip);
            p
        })
        .collect();
    r["points"] = json!(points);
    r["width"] = json!(1600);
    r["height"] = json!(900);
    let path = dir.join("results.json");
    std::fs::write(&path, serde_json::to_string(&r).unwrap()).unwrap();
    path
}

fn play(budget: f64, results: &std::path::Path) -> (i32, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_kiln-play"))
        .args(["missing.kiln", "--headless", "--size", "1600x900", "-o", "out.png", "--budget-ms"])
        .arg(budget.to_string())
        .arg("--bench-results")
        .arg(results)
        .output()
        .unwrap();
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn budget_ms_chooses_the_lowest_error_that_fits_per_frame_and_refuses_when_none_does() {
    let dir = tempfile::tempdir().unwrap();
    let results = results_file(dir.path());
    for budget in [0.5, 1.2, 1.6, 2.5, 7.0] {
        let (code, err) = play(budget, &results);
        // Brute force: each technique at its fewest frames, the lowest FLIP among those that fit.
        let mut first: Vec<(&str, u32, f64, f64)> = Vec::new();
        for p in POINTS {
            if !first.iter().any(|q| q.0 == p.0) {
                first.push(p);
            }
        }
        let best = first.iter().filter(|p| p.2 <= budget).min_by(|a, b| a.3.total_cmp(&b.3));
        match best {
            Some(p) => {
                assert_eq!(code, 4, "budget {budget}: {err}");
                assert!(err.contains(&format!("chose {} ", p.0)), "budget {budget}: {err}");
            }
            None => {
                assert_eq!(code, 2, "budget {budget}: {err}");
                assert!(err.contains("no technique set fits") && err.contains("1.000 ms"), "{err}");
            }
        }
    }
}
