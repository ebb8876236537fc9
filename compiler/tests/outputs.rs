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

/// The same files give the same bytes wherever they sit and however their paths are spelled
/// (issue 46): inputs are recorded relative to the scene file's folder (the sidecar to its own).
/// Before, the manifest held
/// each path as given, so `./a.obj` and `/abs/a.obj` gave different files and two checkouts in
/// different places never shared a build cache entry.
#[test]
fn output_does_not_depend_on_where_the_inputs_sit() {
    let root = tempfile::tempdir().unwrap();
    let root = root.path();
    // The layout: a scene folder with its OBJ, MTL and texture, and a sidecar beside the folder.
    let layout = |top: &Path| {
        std::fs::create_dir_all(top.join("scene/tex")).unwrap();
        std::fs::write(
            top.join("scene/room.obj"),
            "mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl lamp\nf 1/1 2/2 3/3\n",
        )
        .unwrap();
        std::fs::write(
            top.join("scene/room.mtl"),
            "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\nmap_Kd tex/t.png\n",
        )
        .unwrap();
        image::RgbImage::from_pixel(2, 2, image::Rgb([200, 100, 50]))
            .save(top.join("scene/tex/t.png"))
            .unwrap();
        std::fs::write(
            top.join("room.toml"),
            "[camera]\nposition = [0.3, 0.3, 2.0]\ntarget = [0.3, 0.3, 0.0]\n[sky]\nradiance = [0.1, 0.1, 0.1]\n",
        )
        .unwrap();
    };
    let (a, b) = (root.join("a"), root.join("b/deeper/checkout"));
    layout(&a);
    layout(&b);
    // The sidecar kept in another folder, at another depth.
    std::fs::create_dir_all(b.join("configs/scenes")).unwrap();
    std::fs::rename(b.join("room.toml"), b.join("configs/scenes/room.toml")).unwrap();
    std::fs::create_dir_all(a.join("elsewhere")).unwrap();
    let abs = |p: &Path| p.to_str().unwrap().to_string();
    let (a_obj, a_toml) = (abs(&a.join("scene/room.obj")), abs(&a.join("room.toml")));
    let runs: [(&Path, Vec<&str>); 6] = [
        (&a, vec!["scene/room.obj", "--config", "room.toml"]),
        (&a.join("scene"), vec!["./room.obj", "--config", "../room.toml"]),
        (&a.join("elsewhere"), vec![&a_obj, "--config", &a_toml]),
        (&a, vec!["elsewhere/../scene/./room.obj", "--config", "scene/../room.toml"]),
        (&b, vec!["scene/room.obj", "--config", "configs/scenes/room.toml"]),
        (&b.join("configs"), vec!["../scene/room.obj", "--config", "scenes/room.toml"]),
    ];
    let mut files = Vec::new();
    for (i, (dir, args)) in runs.iter().enumerate() {
        let out = root.join(format!("out{i}.kiln"));
        let mut all = vec!["compile"];
        all.extend(args.iter().copied());
        all.extend(["-q", "-o", out.to_str().unwrap()]);
        kiln(dir, &all).expect(0);
        files.push(std::fs::read(&out).unwrap());
    }
    for (i, f) in files.iter().enumerate().skip(1) {
        assert!(f == &files[0], "run {i} ({:?}) differs from run 0", runs[i].1);
    }
    // What the manifest records: the asset's files from its folder, the sidecar from its own.
    let run = kiln(root, &["inspect", "--json", "out0.kiln"]);
    let json: serde_json::Value = serde_json::from_str(&run.expect(0).stdout).unwrap();
    let mut paths: Vec<&str> =
        json["manifest"]["inputs"].as_array().unwrap().iter().map(|i| i["path"].as_str().unwrap()).collect();
    paths.sort_unstable();
    assert_eq!(paths, ["room.mtl", "room.obj", "room.toml", "tex/t.png"]);
}
