//! Progress on stderr: counted bars for the long stages in a terminal, nothing in a build log.

use std::process::Command;

/// `kiln` with `args`, stderr piped (not a terminal).
fn piped(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(args)
        .current_dir(dir)
        .env_remove("KILN_CACHE")
        .output()
        .expect("kiln runs")
}

#[test]
fn a_build_log_gets_no_progress() {
    let dir = tempfile::tempdir().unwrap();
    let out = piped(dir.path(), &["demo", "--scene", "box-teapot", "-o", "t.kiln", "--threads", "2"]);
    assert!(out.status.success());
    assert_eq!(String::from_utf8_lossy(&out.stderr), "", "stderr is not a terminal: nothing but warnings");
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("wrote t.kiln"));
}

/// Runs `kiln` in a pseudo-terminal (util-linux `script`); what the terminal showed, or `None`
/// when `script` is missing.
fn in_terminal(dir: &std::path::Path, args: &str) -> Option<String> {
    let cmd = format!("{} {args}", env!("CARGO_BIN_EXE_kiln"));
    let out = Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .current_dir(dir)
        .env_remove("KILN_CACHE")
        .output();
    match out {
        Ok(o) if o.status.success() => Some(String::from_utf8_lossy(&o.stdout).into_owned()),
        Ok(o) => panic!("kiln failed in a terminal: {}", String::from_utf8_lossy(&o.stdout)),
        Err(e) => {
            eprintln!("skipped: no `script` to give kiln a terminal ({e})");
            None
        }
    }
}

#[test]
fn a_terminal_shows_counted_bars_for_the_long_stages() {
    let dir = tempfile::tempdir().unwrap();
    // The teapot box's line space takes long enough (seconds) for the bar to be drawn.
    let Some(screen) =
        in_terminal(dir.path(), "demo --scene box-teapot -o t.kiln --threads 2 --shadow-res 2048")
    else {
        return;
    };
    let counted = |what: &str| {
        screen.split(['\r', '\n']).any(|l| {
            l.contains(what)
                && l.split_whitespace().any(|w| {
                    w.split_once('/').is_some_and(|(a, b)| {
                        let n = |s: &str| s.replace(',', "").parse::<u64>().ok();
                        matches!((n(a), n(b)), (Some(x), Some(y)) if x <= y && y > 0)
                    })
                })
        })
    };
    assert!(counted("line space: cells"), "no counted line-space bar in:\n{screen:?}");
    assert!(counted("shadow maps: texels"), "no counted shadow-map bar in:\n{screen:?}");
}
