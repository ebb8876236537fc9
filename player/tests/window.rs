//! The window front end under a virtual X server: `kiln-play FILE --frames N` opens a window,
//! presents N frames through the swapchain with the validation layer on, and exits cleanly;
//! with ray-traced techniques the first frames come from their fallback, which it notes.
//! Needs `xvfb-run` and a Vulkan device; without them the test says so and passes, unless
//! `KILN_REQUIRE_VULKAN` is set (as `.ci/run` does).

use std::process::Command;

use kiln_test_support::{gpu_test, require, xvfb_run};

mod common;

#[test]
fn window_presents_frames_and_exits_cleanly_under_xvfb() {
    require!(xvfb_run());
    let dir = gpu_test!();
    let file = dir.path().join("demo.kiln");
    common::kiln(&["demo", "-q", "--shaft-variants", "none", "-o", file.to_str().unwrap()]);
    // The default frame, and the hybrid one (every ray-traced pass, the visibility buffer).
    let hybrid = ["--shadows", "rt", "--ao", "rt", "--reflections", "rt", "--gbuffer", "visibility"];
    for extra in [&[][..], &hybrid[..]] {
        let out = Command::new("xvfb-run")
            .args(["-a", "-s", "-screen 0 640x480x24", env!("CARGO_BIN_EXE_kiln-play")])
            .arg(&file)
            .args(["--frames", "12", "--validate", "--no-pipeline-cache", "--size", "200x150"])
            .args(extra)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "kiln-play {extra:?} in a window failed ({:?}): {stderr}", out.status);
        assert!(!stderr.contains("validation error"), "{stderr}");
        // The ray-traced frame starts from its fallback, and says so (12 frames may end before
        // its pipelines are ready: closing then must stay clean too).
        let fallback = stderr.contains("note: the ray-traced passes' pipelines compile in the background");
        assert_eq!(fallback, !extra.is_empty(), "{extra:?}: {stderr}");
    }
}
