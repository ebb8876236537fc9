//! kiln under a real build engine (issue 46): Bazel (Debian's `bazel-bootstrap`, 4.2.3) builds
//! the example workspace `examples/bazel` with the rules of `bazel/kiln.bzl`, sandboxed, and
//! BuildGrid (PyPI `buildgrid`) serves as its REAPI remote cache on 127.0.0.1:
//! - the sandboxed build's `.kiln` is the direct `kiln compile`'s, byte for byte;
//! - after `bazel clean --expunge` every action is a remote cache hit, with the same bytes;
//! - a second copy of the workspace in another folder hits the cache too (the output does not
//!   depend on where the files sit).
//!
//! Every Bazel command runs with `--batch` (no server left behind) under the test's own output
//! root, and BuildGrid is stopped by its process group's id, also when the test fails.
//! Needs `bazel` and BuildGrid's `bgd` (`.venv-buildgrid`, or `KILN_BGD`); without them the test
//! says so and passes, unless `KILN_REQUIRE_BAZEL` is set (as `.ci/run` does).

use std::net::{TcpListener, TcpStream};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use kiln_test_support::require;

/// BuildGrid's server as a remote cache (content-addressed store, action cache, byte stream) on
/// `port`, held in memory; stopped with its whole process group when dropped.
struct BuildGrid {
    child: Child,
    port: u16,
}

impl BuildGrid {
    fn start(bgd: &Path, dir: &Path) -> BuildGrid {
        // A port the system says is free; BuildGrid binds it a moment later.
        let port = TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
        let config = dir.join("buildgrid.yml");
        let template =
            std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bazel/cache.yml"))
                .unwrap();
        std::fs::write(&config, template.replace("PORT", &port.to_string())).unwrap();
        let log = std::fs::File::create(dir.join("buildgrid.log")).unwrap();
        let child = Command::new(bgd)
            .args(["server", "start"])
            .arg(&config)
            .stdout(log.try_clone().unwrap())
            .stderr(log)
            .process_group(0)
            .spawn()
            .expect("bgd starts");
        let mut server = BuildGrid { child, port };
        let start = Instant::now();
        while TcpStream::connect(("127.0.0.1", port)).is_err() {
            let log = || std::fs::read_to_string(dir.join("buildgrid.log")).unwrap_or_default();
            assert!(server.child.try_wait().unwrap().is_none(), "BuildGrid exited: {}", log());
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "BuildGrid not listening after 60 s: {}",
                log()
            );
            std::thread::sleep(Duration::from_millis(200));
        }
        server
    }
}

impl Drop for BuildGrid {
    fn drop(&mut self) {
        // The group: BuildGrid's server and anything it started.
        let _ = Command::new("kill").arg("--").arg(format!("-{}", self.child.id())).status();
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Copies the files under `from` to `to`, leaving out Bazel's convenience links (`bazel-*`).
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let name = e.file_name();
        if name.to_string_lossy().starts_with("bazel-") {
            continue;
        }
        let t = e.file_type().unwrap();
        if t.is_dir() {
            copy_tree(&e.path(), &to.join(&name));
        } else if t.is_file() {
            std::fs::copy(e.path(), to.join(&name)).unwrap();
        }
    }
}

/// A copy of the repository's Bazel files at `root/<path>` (the rules, the example workspace and
/// `target/release/kiln`, where the example's WORKSPACE looks for the binary); returns the
/// example workspace's folder.
fn checkout(root: &Path, path: &str) -> PathBuf {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let at = root.join(path);
    copy_tree(&repo.join("bazel"), &at.join("bazel"));
    copy_tree(&repo.join("examples/bazel"), &at.join("examples/bazel"));
    std::fs::create_dir_all(at.join("target/release")).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_kiln"), at.join("target/release/kiln")).unwrap();
    at.join("examples/bazel")
}

/// Runs `bazel --batch` in `ws` under the output root `out_root` (the system's rc file, which says
/// where Debian installed Bazel, but no user's or workspace's) and returns its stderr; fails the
/// test if Bazel fails.
fn bazel(ws: &Path, out_root: &Path, args: &[&str]) -> String {
    let o = Command::new("bazel")
        .args(["--batch", "--nohome_rc", "--noworkspace_rc"])
        .arg(format!("--output_user_root={}", out_root.display()))
        .args(args)
        .current_dir(ws)
        .stdin(Stdio::null())
        .output()
        .expect("bazel runs");
    // Debian's rc file turns on --sandbox_debug, a trace of every action: Bazel's own lines only.
    let stderr: String = String::from_utf8_lossy(&o.stderr)
        .lines()
        .filter(|l| !l.contains("src/main/tools/"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(o.status.success(), "bazel {args:?} failed in {}:\n{stderr}", ws.display());
    stderr
}

/// Bazel's summary "INFO: 2 processes: 1 remote cache hit, 1 internal." as (kind, count) pairs,
/// the internal ones left out.
fn processes(stderr: &str) -> Vec<(String, u32)> {
    let line = stderr
        .lines()
        .find_map(|l| {
            l.strip_prefix("INFO: ").and_then(|l| l.split_once(" processes: ").or(l.split_once(" process: ")))
        })
        .unwrap_or_else(|| panic!("no process summary in:\n{stderr}"))
        .1;
    line.trim_end_matches('.')
        .split(", ")
        .filter_map(|part| {
            let (n, kind) = part.split_once(' ')?;
            (kind != "internal").then(|| (kind.to_string(), n.parse().unwrap()))
        })
        .collect()
}

#[test]
fn bazel_builds_the_example_sandboxed_and_every_action_hits_the_remote_cache_from_any_checkout() {
    let bgd = require!(kiln_test_support::bazel_and_buildgrid());
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    let out_root = t.join("bazel-root");
    let server = BuildGrid::start(&bgd, t);
    let cache = format!("--remote_cache=grpc://127.0.0.1:{}", server.port);
    let build = |ws: &Path| bazel(ws, &out_root, &["build", "//:room", "--spawn_strategy=sandboxed", &cache]);

    // A cold, sandboxed build: the action runs (and its result is uploaded).
    let a = checkout(t, "a/kiln");
    let ran = processes(&build(&a));
    assert!(ran.len() == 1 && ran[0].1 == 1 && ran[0].0.contains("sandbox"), "one sandboxed action: {ran:?}");
    let built = std::fs::read(a.join("bazel-bin/room.kiln")).unwrap();
    // The bytes of a direct compile with the rule's flags.
    let direct = a.join("direct.kiln");
    let o = Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(["compile", "room/room.obj", "--config", "room.toml", "--strict", "-q", "-o"])
        .arg(&direct)
        .current_dir(&a)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read(&direct).unwrap() == built, "Bazel's room.kiln differs from kiln compile's");

    // Everything local gone: the rebuild is all remote cache hits, the same bytes.
    bazel(&a, &out_root, &["clean", "--expunge"]);
    let hits = processes(&build(&a));
    assert_eq!(hits, [("remote cache hit".to_string(), 1)], "after clean --expunge");
    assert!(std::fs::read(a.join("bazel-bin/room.kiln")).unwrap() == built, "bytes from the cache");

    // Another checkout, elsewhere and deeper: the same action, so the same cache entry.
    let b = checkout(t, "b/ci/work/kiln-copy");
    let hits = processes(&build(&b));
    assert_eq!(hits, [("remote cache hit".to_string(), 1)], "from a checkout in another folder");
    assert!(std::fs::read(b.join("bazel-bin/room.kiln")).unwrap() == built, "bytes in the other checkout");
    drop(server);
}
