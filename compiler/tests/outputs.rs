//! Outputs never replace inputs, and `-q` never hides a warning (issue 40): `kiln compile
//! scene.obj -o scene.obj` used to overwrite the asset and exit 0.

#[path = "util/run.rs"]
mod run;

use std::path::Path;

use run::kiln;

/// A one-triangle OBJ whose MTL names a texture that is not there (a data-loss warning), lit by
/// an emissive material; returns the OBJ's and the MTL's bytes.
fn scene(dir: &Path) -> (Vec<u8>, Vec<u8>) {
    let obj = b"mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\n".to_vec();
    let mtl = b"newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\nmap_Kd missing.png\n".to_vec();
    std::fs::write(dir.join("scene.obj"), &obj).unwrap();
    std::fs::write(dir.join("scene.mtl"), &mtl).unwrap();
    (obj, mtl)
}

#[test]
fn an_output_naming_an_input_is_refused_and_the_input_kept() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (obj, mtl) = scene(d);
    std::fs::create_dir(d.join("sub")).unwrap();
    for args in [
        &["compile", "scene.obj", "-o", "scene.obj"][..],
        &["compile", "scene.obj", "-o", "sub/../scene.obj"],
        &["compile", "scene.obj", "-o", "out.kiln", "--report", "scene.mtl"],
        &["compile", "scene.obj", "-o", "out.kiln", "--depfile", "./scene.mtl"],
    ] {
        kiln(d, args).expect(2).says("would overwrite the input");
        assert_eq!(std::fs::read(d.join("scene.obj")).unwrap(), obj, "{args:?}");
        assert_eq!(std::fs::read(d.join("scene.mtl")).unwrap(), mtl, "{args:?}");
        assert!(!d.join("out.kiln").exists(), "{args:?}: nothing is written");
    }
    // Two outputs on one path.
    kiln(d, &["compile", "scene.obj", "-o", "out.kiln", "--report", "out.kiln"]).expect(2).says("same file");
    // A link to the input is the input.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(d.join("scene.obj"), d.join("link.kiln")).unwrap();
        kiln(d, &["compile", "scene.obj", "-o", "link.kiln"]).expect(2).says("would overwrite the input");
        assert_eq!(std::fs::read(d.join("scene.obj")).unwrap(), obj);
    }
    // And a sound command line still compiles; `kiln export` will not write over its .kiln.
    kiln(d, &["compile", "scene.obj", "-o", "out.kiln", "-q"]).expect(0);
    let kiln_bytes = std::fs::read(d.join("out.kiln")).unwrap();
    kiln(d, &["export", "out.kiln", "shadow-map", "-o", "out.kiln"])
        .expect(2)
        .says("would overwrite the input");
    assert_eq!(std::fs::read(d.join("out.kiln")).unwrap(), kiln_bytes);
}

#[test]
fn quiet_hides_progress_never_warnings() {
    let dir = tempfile::tempdir().unwrap();
    scene(dir.path());
    let run = kiln(dir.path(), &["compile", "scene.obj", "-o", "out.kiln", "-q"]);
    run.expect(0).says("warning:").says("missing.png");
    assert!(run.stdout.is_empty(), "-q prints no summary: {}", run.stdout);
    // -W data-loss=ignore is what hides them.
    let run = kiln(dir.path(), &["compile", "scene.obj", "-o", "out.kiln", "-q", "-W", "data-loss=ignore"]);
    assert!(!run.expect(0).stderr.contains("missing.png"), "{}", run.stderr);
}
