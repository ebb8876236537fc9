//! `kiln compile` as a build action under ninja (docs/compiler.md's "Build systems" rule, run as
//! written): the depfile names every input the compile read (OBJ, MTL, texture, sidecar), so
//! ninja rebuilds when any of them changes and only then, and a clean rebuild gives the same
//! bytes. Needs `ninja` (Debian `ninja-build`); without it the test says so and passes, unless
//! `KILN_REQUIRE_NINJA` is set (as `.ci/run` does).

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use kiln_test_support::require;

/// Runs ninja in `dir`; returns its stdout.
fn ninja(dir: &Path) -> String {
    let o = Command::new("ninja").arg("-C").arg(dir).output().expect("ninja runs");
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(o.status.success(), "ninja failed: {out}{}", String::from_utf8_lossy(&o.stderr));
    out
}

/// Rewrites `path` with `bytes` a moment after the last build (ninja compares modification
/// times at nanosecond resolution where the file system has it; the pause covers coarser ones).
fn change(path: &Path, bytes: &[u8]) {
    std::thread::sleep(Duration::from_millis(1100));
    std::fs::write(path, bytes).unwrap();
}

/// A 2 × 2 RGBA PNG of one colour.
fn png(rgb: [u8; 3]) -> Vec<u8> {
    let mut bytes = Vec::new();
    let img = image::RgbaImage::from_pixel(2, 2, image::Rgba([rgb[0], rgb[1], rgb[2], 255]));
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).unwrap();
    bytes
}

#[test]
fn ninja_rebuilds_exactly_when_an_input_the_depfile_names_changes() {
    require!(kiln_test_support::ninja());
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let obj = "mtllib scene.mtl\nusemtl painted\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
    std::fs::write(d.join("scene.obj"), obj).unwrap();
    std::fs::write(d.join("scene.mtl"), "newmtl painted\nKd 1 1 1\nmap_Kd paint.png\n").unwrap();
    std::fs::write(d.join("paint.png"), png([200, 40, 40])).unwrap();
    std::fs::write(d.join("scene.toml"), "[sky]\nradiance = [0.5, 0.5, 0.5]\n").unwrap();
    std::fs::write(d.join("unrelated.txt"), "not an input").unwrap();
    // The rule of docs/compiler.md's "Build systems" section.
    let rule = format!(
        "rule kiln\n  command = {} compile $in --config scene.toml -o $out --depfile $out.d -q --shaft-variants none\n  depfile = $out.d\n  deps = gcc\n  description = kiln $in\n\nbuild scene.kiln: kiln scene.obj\n",
        env!("CARGO_BIN_EXE_kiln")
    );
    std::fs::write(d.join("build.ninja"), rule).unwrap();

    assert!(ninja(d).contains("kiln scene.obj"), "the first build compiles");
    let first = std::fs::read(d.join("scene.kiln")).unwrap();
    assert!(ninja(d).contains("no work to do"), "nothing changed");
    change(&d.join("unrelated.txt"), b"still not an input");
    assert!(ninja(d).contains("no work to do"), "a file the compile did not read");
    for (input, text) in [
        ("scene.mtl", "newmtl painted\nKd 0.5 0.5 0.5\nmap_Kd paint.png\n"),
        ("scene.toml", "[sky]\nradiance = [0.25, 0.25, 0.25]\n"),
    ] {
        change(&d.join(input), text.as_bytes());
        assert!(ninja(d).contains("kiln scene.obj"), "{input} changed: rebuilt");
        assert!(ninja(d).contains("no work to do"), "{input}: once");
    }
    change(&d.join("paint.png"), &png([40, 200, 40]));
    assert!(ninja(d).contains("kiln scene.obj"), "the texture changed: rebuilt");
    let changed = std::fs::read(d.join("scene.kiln")).unwrap();
    assert_ne!(first, changed, "the inputs changed, so must the file");
    // A clean rebuild of the same inputs gives the same bytes (what a remote cache relies on).
    let o = Command::new("ninja").arg("-C").arg(d).args(["-t", "clean"]).output().unwrap();
    assert!(o.status.success());
    assert!(!d.join("scene.kiln").exists());
    ninja(d);
    assert_eq!(std::fs::read(d.join("scene.kiln")).unwrap(), changed, "deterministic output");
}
