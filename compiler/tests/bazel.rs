//! kiln under a real build engine (issue 46): Bazel (Debian's `bazel-bootstrap`, 4.2.3) builds
//! the example workspace `examples/bazel` with the rules of `bazel/kiln.bzl`, and BuildGrid (PyPI
//! `buildgrid`) serves it on 127.0.0.1 as a REAPI remote cache and remote executor (its scheduler
//! on a private PostgreSQL cluster, its one worker `tests/bazel/worker.py`):
//! - a local, sandboxed build's `.kiln` is the direct `kiln compile`'s, byte for byte;
//! - a second checkout in another folder builds with `--remote_executor`: the action runs on the
//!   worker (in a plain folder of copied inputs), with the same bytes;
//! - after `bazel clean --expunge` the first checkout's build is all remote cache hits (of the
//!   other checkout's action: the output does not depend on where the files sit), same bytes.
//!
//! Every Bazel command runs with `--batch` (no server left behind) under the test's own output
//! root and is killed after 3 minutes; BuildGrid and the worker are stopped by their process
//! groups' ids and PostgreSQL by `pg_ctl stop`, also when the test fails. Needs `bazel`,
//! PostgreSQL's server binaries and BuildGrid's `bgd` (`.venv-buildgrid`, or `KILN_BGD`); without
//! them the test says so and passes, unless `KILN_REQUIRE_BAZEL` is set (as `.ci/run` does).

use std::net::{TcpListener, TcpStream};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use kiln_test_support::require;

/// A port the system says is free (its user binds it a moment later).
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// A command running `program`, as the `postgres` user when `as_postgres` (the test runs as
/// root, which PostgreSQL refuses).
fn pg_command(program: &Path, as_postgres: bool) -> Command {
    if as_postgres {
        let mut c = Command::new("runuser");
        c.args(["-u", "postgres", "--"]).arg(program);
        c
    } else {
        Command::new(program)
    }
}

/// Runs `cmd` with `args` as [`pg_command`] does; fails the test with its output if it fails.
fn run_pg(cmd: &Path, args: &[&str], as_postgres: bool) {
    let o = pg_command(cmd, as_postgres)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("{} does not start: {e}", cmd.display()));
    assert!(
        o.status.success(),
        "{} {args:?} failed:\n{}{}",
        cmd.display(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A private PostgreSQL cluster in `dir/pg`, listening only on a Unix socket there; stopped when
/// dropped.
struct Postgres {
    bin: PathBuf,
    data: PathBuf,
    as_postgres: bool,
}

impl Postgres {
    /// Starts the cluster with a database `bgd`; returns it and the SQLAlchemy URL of the database.
    fn start(bin: PathBuf, dir: &Path) -> (Postgres, String) {
        let whoami = Command::new("id").arg("-u").output().unwrap();
        let as_postgres = String::from_utf8_lossy(&whoami.stdout).trim() == "0";
        let pg = dir.join("pg");
        std::fs::create_dir(&pg).unwrap();
        if as_postgres {
            // The test's folder is private to root; the server's user must reach pg/ inside it.
            std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o711)).unwrap();
            assert!(Command::new("chown").args(["postgres"]).arg(&pg).status().unwrap().success());
        }
        let data = pg.join("data");
        let d = data.to_str().unwrap();
        run_pg(
            &bin.join("initdb"),
            &["-D", d, "-U", "bgd", "--auth=trust", "-E", "UTF8", "--no-sync"],
            as_postgres,
        );
        let port = free_port().to_string();
        let opts = format!("-p {port} -k {} -c listen_addresses=''", pg.display());
        let log = pg.join("log");
        let cluster = Postgres { bin: bin.clone(), data: data.clone(), as_postgres };
        run_pg(
            &bin.join("pg_ctl"),
            &["-D", d, "-o", &opts, "-l", log.to_str().unwrap(), "-w", "start"],
            as_postgres,
        );
        let sock = pg.to_str().unwrap();
        run_pg(&bin.join("createdb"), &["-h", sock, "-p", &port, "-U", "bgd", "bgd"], as_postgres);
        (cluster, format!("postgresql+psycopg2://bgd@/bgd?host={sock}&port={port}"))
    }
}

impl Drop for Postgres {
    fn drop(&mut self) {
        let args = ["-D", self.data.to_str().unwrap(), "-m", "immediate", "stop"];
        let _ = pg_command(&self.bin.join("pg_ctl"), self.as_postgres).args(args).output();
    }
}

/// A process started in its own group; the group is killed when dropped.
struct Group(Child);

impl Group {
    fn spawn(cmd: &mut Command, log: &Path) -> Group {
        let log = std::fs::File::create(log).unwrap();
        let child = cmd
            .stdout(log.try_clone().unwrap())
            .stderr(log)
            .stdin(Stdio::null())
            .process_group(0)
            .spawn()
            .unwrap_or_else(|e| panic!("{cmd:?} does not start: {e}"));
        Group(child)
    }
}

impl Drop for Group {
    fn drop(&mut self) {
        let _ = Command::new("kill").arg("--").arg(format!("-{}", self.0.id())).status();
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// BuildGrid (`tests/bazel/buildgrid.yml`) on a free port with its scheduler in `dsn`, and the
/// worker; returns them (stopped when dropped) and the port.
fn buildgrid(bgd: &Path, dsn: &str, dir: &Path) -> (Group, Group, u16) {
    let tests = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bazel");
    let o = Command::new(bgd).args(["migrate", "apply", dsn]).output().unwrap();
    assert!(o.status.success(), "bgd migrate: {}", String::from_utf8_lossy(&o.stderr));
    let port = free_port();
    let template = std::fs::read_to_string(tests.join("buildgrid.yml")).unwrap();
    let config = dir.join("buildgrid.yml");
    std::fs::write(&config, template.replace("PORT", &port.to_string()).replace("DSN", dsn)).unwrap();
    let log = dir.join("buildgrid.log");
    let mut server = Group::spawn(Command::new(bgd).args(["server", "start"]).arg(&config), &log);
    let start = Instant::now();
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        let text = || std::fs::read_to_string(&log).unwrap_or_default();
        assert!(server.0.try_wait().unwrap().is_none(), "BuildGrid exited: {}", text());
        assert!(start.elapsed() < Duration::from_secs(60), "BuildGrid not listening after 60 s: {}", text());
        std::thread::sleep(Duration::from_millis(200));
    }
    // The worker runs with the Python of BuildGrid's environment (it imports BuildGrid's protocols).
    let python = bgd.parent().unwrap().join("python");
    let work = dir.join("worker");
    std::fs::create_dir(&work).unwrap();
    let worker = Group::spawn(
        Command::new(python)
            .arg("-u")
            .arg(tests.join("worker.py"))
            .arg(format!("127.0.0.1:{port}"))
            .arg(&work),
        &dir.join("worker.log"),
    );
    (server, worker, port)
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
/// test if Bazel fails or runs past 3 minutes (with the server's and the worker's logs from
/// `logs`).
fn bazel(ws: &Path, out_root: &Path, logs: &Path, args: &[&str]) -> String {
    let err = logs.join(format!("bazel-{}.log", args.join("_").replace(['/', ':', '='], "-")));
    let mut cmd = Command::new("bazel");
    cmd.args(["--batch", "--nohome_rc", "--noworkspace_rc"])
        .arg(format!("--output_user_root={}", out_root.display()))
        .args(args)
        .current_dir(ws);
    let mut bazel = Group::spawn(&mut cmd, &err);
    let start = Instant::now();
    let status = loop {
        if let Some(status) = bazel.0.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > Duration::from_secs(180) {
            break None;
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    // Debian's rc file turns on --sandbox_debug, a trace of every action: Bazel's own lines only.
    let stderr: String = std::fs::read_to_string(&err)
        .unwrap_or_default()
        .lines()
        .filter(|l| !l.contains("src/main/tools/"))
        .map(|l| format!("{l}\n"))
        .collect();
    if status.is_none_or(|s| !s.success()) {
        drop(bazel);
        let log = |name: &str| std::fs::read_to_string(logs.join(name)).unwrap_or_default();
        panic!(
            "bazel {args:?} in {} {}:\n{stderr}\n--- BuildGrid:\n{}\n--- worker:\n{}",
            ws.display(),
            if status.is_none() { "ran past 3 minutes" } else { "failed" },
            log("buildgrid.log"),
            log("worker.log")
        );
    }
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
fn bazel_builds_sandboxed_remotely_and_from_the_remote_cache_with_the_same_bytes() {
    let (bgd, postgres) = require!(kiln_test_support::bazel_and_buildgrid());
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    let out_root = t.join("bazel-root");
    // Declared in this order, dropped in the reverse: worker, BuildGrid, PostgreSQL.
    let (_postgres, dsn) = Postgres::start(postgres, t);
    let (_server, _worker, port) = buildgrid(&bgd, &dsn, t);
    let remote = |flag: &str| format!("--{flag}=grpc://127.0.0.1:{port}");

    // A local, sandboxed build.
    let a = checkout(t, "a/kiln");
    let ran = processes(&bazel(&a, &out_root, t, &["build", "//:room", "--spawn_strategy=sandboxed"]));
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

    // Another checkout, elsewhere and deeper, executes the action on the worker.
    let b = checkout(t, "b/ci/work/kiln-copy");
    let ran = processes(&bazel(&b, &out_root, t, &["build", "//:room", &remote("remote_executor")]));
    assert_eq!(ran, [("remote".to_string(), 1)], "executed remotely");
    assert!(std::fs::read(b.join("bazel-bin/room.kiln")).unwrap() == built, "bytes of the remote execution");

    // Everything local gone from the first checkout: its action is the other's, a cache hit.
    bazel(&a, &out_root, t, &["clean", "--expunge"]);
    let hits = processes(&bazel(&a, &out_root, t, &["build", "//:room", &remote("remote_cache")]));
    assert_eq!(hits, [("remote cache hit".to_string(), 1)], "after clean --expunge");
    assert!(std::fs::read(a.join("bazel-bin/room.kiln")).unwrap() == built, "bytes from the cache");
}
