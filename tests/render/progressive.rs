//! Progressive pipelines (`PipelineStart::Progressive`): the first frames come from a fallback
//! without ray-traced passes while the chosen techniques' pipelines compile on another thread.
//! Headless output and benchmark frames must still come from the chosen techniques, the session
//! must switch by itself, and no path may leak what the pipeline thread built. The sections only
//! the chosen techniques read are uploaded after the fallback's first frame.

use std::time::{Duration, Instant};

use kiln_compiler::import::demo::cornell_box;
use kiln_player::bench;
use kiln_player::session::Session;
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile};

use crate::harness::{WrittenExr, fast_settings, traced, written_exr};

/// The demo box (one rect light with its baked shadow map) written to `dir`.
fn demo(dir: &std::path::Path) -> std::path::PathBuf {
    let file = dir.join("demo.kiln");
    std::fs::write(&file, compile(cornell_box(), fast_settings())).unwrap();
    file
}

#[test]
fn headless_output_behind_a_fallback_is_bit_identical_to_waiting_for_every_pipeline() {
    let dir = gpu_test!();
    let file = demo(dir.path());
    let (w, h, frames) = (64, 48, 3);
    // GI too: its bounces shade hits with the materials and triangles that upload after the
    // first frame (the box's Lambertian walls give the other passes no use for them).
    let all = |o: Options| traced(o).rt_gi(1);
    let WrittenExr { bytes: progressive, times, behind } =
        written_exr(dir.path(), "progressive", all(Options::new(&file, w, h)).progressive(), frames);
    let WrittenExr { bytes: complete, times: complete_times, .. } =
        written_exr(dir.path(), "complete", all(Options::new(&file, w, h)), frames);
    // What the fallback shows differs from the chosen techniques, so that the comparison below
    // would see a fallback frame written.
    let fallback =
        written_exr(dir.path(), "fallback", all(Options::new(&file, w, h)).as_fallback(true), frames).bytes;
    assert_ne!(
        fallback, complete,
        "the fallback renders what the chosen techniques render: the test sees nothing"
    );
    assert!(progressive == complete, "the output behind a fallback differs from the complete one");
    assert!(!behind, "the output was written behind a fallback");
    // One fallback frame was rendered (timed) before the written ones.
    let names: Vec<(&str, &str, &str)> =
        times.fallback.iter().map(|s| (s.effect, s.requested, s.shown)).collect();
    assert_eq!(
        names,
        [
            ("shadows", "rt", "shadowmap"),
            ("ao", "rt", "none"),
            ("reflections", "rt", "none"),
            ("gi", "rt", "none")
        ]
    );
    assert_eq!(times.after_first_frame, ["materials", "triangles", "triangle-materials", "bvh"]);
    assert_eq!(times.fallback_frames, 1);
    assert!(times.first_frame_since_start_ms > 0.0);
    assert!(times.full_frame_since_start_ms > times.first_frame_since_start_ms);
    assert!(times.full_ready_since_start_ms > 0.0 && times.full_pipelines_ms > 0.0);
    assert!(complete_times.fallback.is_empty() && complete_times.fallback_frames == 0);
    assert_eq!(complete_times.full_frame_since_start_ms, complete_times.first_frame_since_start_ms);
    assert_eq!(complete_times.full_pipelines_ms, complete_times.pipelines_ms);
}

#[test]
fn bench_reports_the_first_frame_the_chosen_techniques_and_residency_separately_and_measures_only_them() {
    let dir = gpu_test!();
    let file = demo(dir.path());
    let report =
        bench::run(&traced(Options::new(&file, 48, 32)).progressive().build(), 1, 2, Instant::now()).unwrap();
    assert_eq!(report.validation_errors, 0);
    let json = serde_json::to_value(&report).unwrap();
    // The measured frames ran the chosen techniques' passes.
    let passes: Vec<&str> =
        json["passes"].as_array().unwrap().iter().map(|p| p["pass"].as_str().unwrap()).collect();
    for pass in ["shadows", "ao", "reflections"] {
        assert!(passes.contains(&pass), "{pass} not measured: {passes:?}");
    }
    let load = &json["load"];
    let fallback: Vec<(String, String, String)> = load["fallback"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let f = |k: &str| s[k].as_str().unwrap().to_string();
            (f("effect"), f("requested"), f("shown"))
        })
        .collect();
    let expected = [("shadows", "rt", "shadowmap"), ("ao", "rt", "none"), ("reflections", "rt", "none")];
    assert_eq!(fallback, expected.map(|(a, b, c)| (a.to_string(), b.to_string(), c.to_string())));
    let ms = |k: &str| load[k].as_f64().unwrap_or_else(|| panic!("{k} missing from {load}"));
    assert!(ms("first_frame_since_start_ms") > 0.0);
    assert!(ms("full_ready_since_start_ms") > 0.0 && ms("full_pipelines_ms") > 0.0);
    assert!(ms("full_frame_since_start_ms") > ms("first_frame_since_start_ms"));
    assert_eq!(load["fallback_frames"].as_u64(), Some(1));
    // The first frame did not wait for what only the ray-traced passes read (the BVH, and the
    // triangles and materials as storage buffers): the scene became resident after it.
    let later: Vec<&str> =
        load["after_first_frame"].as_array().unwrap().iter().map(|s| s.as_str().unwrap()).collect();
    assert_eq!(later, ["materials", "triangles", "triangle-materials", "bvh"]);
    assert!(ms("resident_since_start_ms") > ms("first_frame_since_start_ms"));
    assert!(ms("rest_upload_ms") > 0.0);
    let sections = json["sections"].as_array().unwrap();
    let flagged: Vec<&str> = sections
        .iter()
        .filter(|s| s["after_first_frame"] == true)
        .map(|s| s["section"].as_str().unwrap())
        .collect();
    assert_eq!(flagged, later);
    // Without a ray-traced technique there is nothing to fall back from.
    let plain = bench::run(&Options::new(&file, 48, 32).progressive().build(), 1, 2, Instant::now()).unwrap();
    let load = serde_json::to_value(&plain).unwrap()["load"].clone();
    assert_eq!(load["fallback"].as_array().map(Vec::len), Some(0), "{load}");
    assert_eq!(load["fallback_frames"].as_u64(), Some(0));
    assert_eq!(load["full_frame_since_start_ms"], load["first_frame_since_start_ms"]);
    assert_eq!(load["after_first_frame"].as_array().map(Vec::len), Some(0), "{load}");
    let (resident, first) = (
        load["resident_since_start_ms"].as_f64().unwrap(),
        load["first_frame_since_start_ms"].as_f64().unwrap(),
    );
    assert!(resident < first, "without a fallback the first frame waits for everything: {resident} {first}");
}

#[test]
fn a_session_switches_from_the_fallback_by_itself_at_the_current_size() {
    let dir = gpu_test!();
    let file = demo(dir.path());
    let mut session =
        Session::open(&traced(Options::new(&file, 64, 48)).progressive().build(), Instant::now()).unwrap();
    assert!(session.showing_fallback());
    let fallback_passes = session.renderer.pass_names();
    assert!(!fallback_passes.contains(&"ao") && !fallback_passes.contains(&"shadows"), "{fallback_passes:?}");
    // Resized before the chosen techniques' frame (built at 64 × 48) is switched to.
    session.resize(40, 30).unwrap();
    let give_up = Instant::now() + Duration::from_secs(300);
    while session.showing_fallback() {
        assert!(Instant::now() < give_up, "no switch from the fallback within 5 minutes");
        session.frame(false).unwrap();
        std::thread::sleep(Duration::from_millis(20));
    }
    // Switched at the start of the last frame: it is the chosen techniques' first.
    let passes = session.renderer.pass_names();
    for pass in ["shadows", "ao", "reflections"] {
        assert!(passes.contains(&pass), "{pass} missing after the switch: {passes:?}");
    }
    assert_eq!((session.renderer.images().width, session.renderer.images().height), (40, 30));
    assert_eq!(session.renderer.accumulated(), 1, "the running average restarts at the switch");
    session.frame(false).unwrap();
    assert_eq!(session.renderer.accumulated(), 2);
    assert!(session.notes.iter().any(|n| n.contains("were ready")), "{:?}", session.notes);
    assert_eq!(session.close(), 0, "validation errors");
}

#[test]
fn closing_a_session_while_its_pipelines_compile_leaks_nothing() {
    let dir = gpu_test!();
    let file = demo(dir.path());
    let o = traced(Options::new(&file, 64, 48)).rt_gi(1).progressive().build();
    let session = Session::open(&o, Instant::now()).unwrap();
    assert!(session.showing_fallback());
    assert_eq!(session.close(), 0, "validation errors at teardown (the pipeline thread's frame leaked?)");
}
