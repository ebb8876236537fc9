//! Finders of the programs the tests run, each applying the requirement rule, and what the tests
//! do with Chromium.

use std::io::ErrorKind;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::Need;

/// The workspace's root folder.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("test-support/ lies in the workspace").to_owned()
}

/// Whether `program` starts (run with `args`, its output dropped). Only a program that cannot be
/// started is missing: one that starts and then fails is left to fail the test that uses it.
fn starts(program: &str, args: &[&str]) -> Result<(), String> {
    match Command::new(program).args(args).stdout(Stdio::null()).stderr(Stdio::null()).status() {
        Ok(_) => Ok(()),
        Err(e) if e.kind() == ErrorKind::NotFound => Err(format!("{program} is not installed")),
        Err(e) => Err(format!("{program} cannot be started ({e})")),
    }
}

/// Whether `glslc` is here, by the rule ([`Need::Glslc`]).
pub fn glslc() -> bool {
    Need::Glslc.check(starts("glslc", &["--version"])).is_some()
}

/// Whether `ninja` is here, by the rule ([`Need::Ninja`]).
pub fn ninja() -> bool {
    Need::Ninja.check(starts("ninja", &["--version"])).is_some()
}

/// BuildGrid's `bgd` (`KILN_BGD`, or else `.venv-buildgrid`'s, which `.ci/run` makes) and the
/// folder of PostgreSQL's server binaries (`/usr/lib/postgresql/<version>/bin`, the newest), where
/// `bazel` is on `PATH` too, by the rule ([`Need::Bazel`]).
pub fn bazel_and_buildgrid() -> Option<(PathBuf, PathBuf)> {
    let bgd = std::env::var_os("KILN_BGD")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace().join(".venv-buildgrid/bin/bgd"));
    let postgres = || {
        let mut found: Vec<PathBuf> = std::fs::read_dir("/usr/lib/postgresql")
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path().join("bin"))
            .filter(|b| b.join("initdb").is_file() && b.join("pg_ctl").is_file())
            .collect();
        found.sort_by_key(|b| b.parent().and_then(|v| v.file_name()?.to_str()?.parse::<u32>().ok()));
        found.pop().ok_or_else(|| "PostgreSQL's server (initdb, pg_ctl) is not installed".to_string())
    };
    let found = starts("bazel", &["--version"])
        .and_then(|()| {
            Command::new(&bgd)
                .arg("--help")
                .output()
                .ok()
                .filter(|o| o.status.success())
                .map(|_| bgd.clone())
                .ok_or_else(|| format!("BuildGrid's bgd does not run ({})", bgd.display()))
        })
        .and_then(|bgd| postgres().map(|pg| (bgd, pg)));
    Need::Bazel.check(found)
}

/// Whether `xvfb-run` is here, by the rule ([`Need::Xvfb`]).
pub fn xvfb_run() -> bool {
    Need::Xvfb.check(starts("xvfb-run", &["--help"])).is_some()
}

/// Chromium's binary (`chromium`, `chromium-browser` or `google-chrome` on `PATH`), by the rule
/// ([`Need::Chromium`]).
pub fn chromium() -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|path| {
        ["chromium", "chromium-browser", "google-chrome"]
            .iter()
            .flat_map(|name| std::env::split_paths(&path).map(move |d| d.join(name)))
            .find(|p| p.is_file())
    });
    Need::Chromium.check(found.ok_or_else(|| "Chromium is not installed".to_string()))
}

/// A 1200 × 1600 screenshot of `html` by headless Chromium (`chromium`, from [`chromium`]) with
/// its profile in `profile`, decoded; written as `shot.png` beside `html`. Fails if Chromium
/// fails or takes over 2 minutes.
pub fn screenshot(chromium: &Path, html: &Path, profile: &Path) -> image::RgbImage {
    let shot = html.with_file_name("shot.png");
    let _ = std::fs::remove_file(&shot);
    let mut child = Command::new(chromium)
        .args([
            "--headless",
            "--disable-gpu",
            "--no-sandbox",
            "--disable-dev-shm-usage",
            "--hide-scrollbars",
            "--no-first-run",
            "--window-size=1200,1600",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", html.display()))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("chromium starts");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let out = child.wait_with_output().unwrap();
            assert!(status.success(), "chromium failed: {}", String::from_utf8_lossy(&out.stderr));
            break;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium took over 2 minutes");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    eprintln!("chromium screenshot: {:.1} s", start.elapsed().as_secs_f64());
    image::open(&shot).expect("chromium wrote the screenshot").to_rgb8()
}

/// The Python with flip-evaluator and numpy, by the rule ([`Need::Mitsuba`]).
pub fn flip_python() -> Option<PathBuf> {
    python_with("flip_evaluator and numpy", "import flip_evaluator, numpy")
}

/// The Python with Mitsuba 3 (imported with its `scalar_rgb` variant; `render.py` renders with
/// `llvm_ad_rgb` and says when libLLVM is missing), flip-evaluator and numpy, by the rule
/// ([`Need::Mitsuba`]).
pub fn mitsuba_python() -> Option<PathBuf> {
    python_with(
        "mitsuba (scalar_rgb), flip_evaluator and numpy",
        "import mitsuba, flip_evaluator, numpy; mitsuba.set_variant('scalar_rgb')",
    )
}

/// The interpreter `KILN_MITSUBA_PYTHON` names, or else `.venv-mitsuba`'s (which `.ci/run`
/// makes), if it runs `probe` (Python code importing `modules`).
fn python_with(modules: &str, probe: &str) -> Option<PathBuf> {
    let (python, origin) = match std::env::var_os("KILN_MITSUBA_PYTHON") {
        Some(p) => (PathBuf::from(p), "KILN_MITSUBA_PYTHON"),
        None => (workspace().join(".venv-mitsuba/bin/python"), ".venv-mitsuba"),
    };
    let found = match Command::new(&python).args(["-c", probe]).output() {
        Ok(o) if o.status.success() => Ok(python),
        Ok(o) => {
            let why = String::from_utf8_lossy(&o.stderr).trim().lines().last().unwrap_or("").to_string();
            Err(format!("{} cannot import {modules}: {why}", python.display()))
        }
        Err(e) if e.kind() == ErrorKind::NotFound => {
            Err(format!("{modules} not installed ({origin} missing: {})", python.display()))
        }
        Err(e) => Err(format!("cannot run {}: {e}", python.display())),
    };
    Need::Mitsuba.check(found)
}
