//! Hostile references in an OBJ/MTL scene finish quickly with a warning or a clear error, never
//! a panic, an abort or a hang (issue 40): a device or FIFO as a library, texture or the input
//! itself, an image declaring more pixels than `--max-image-side`, a file over `--max-file-size`,
//! MTL statements with too few or non-finite values.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The outcome of a `kiln` run that must end within 30 s (killed, and the test failed, if not).
struct Ended {
    code: i32,
    stderr: String,
}

fn kiln(dir: &Path, args: &[&str]) -> Ended {
    let mut child = Command::new(env!("CARGO_BIN_EXE_kiln"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("kiln runs");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut stderr = String::new();
            std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
            assert!(!stderr.contains("panicked") && status.code() != Some(70), "{args:?}: {stderr}");
            return Ended { code: status.code().unwrap_or(-1), stderr };
        }
        if start.elapsed() > Duration::from_secs(30) {
            child.kill().ok();
            panic!("kiln {args:?} did not end within 30 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A lit one-triangle OBJ naming `mtllib` and the material `m`.
fn obj(dir: &Path, mtllib: &str) {
    let text = format!(
        "mtllib {mtllib}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n"
    );
    std::fs::write(dir.join("scene.obj"), text).unwrap();
}

#[cfg(unix)]
fn fifo(path: &Path) {
    let ok = Command::new("mkfifo").arg(path).status().map(|s| s.success()).unwrap_or(false);
    assert!(ok, "mkfifo {}", path.display());
}

#[test]
#[cfg(unix)]
fn devices_and_fifos_are_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A device as the material library: a warning, the default material, no endless read
    // (outside the input's folder, so only with --allow-any-path).
    obj(d, "/dev/zero");
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln", "--allow-any-path"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stderr.contains("/dev/zero is not a regular file"), "{}", run.stderr);
    // A FIFO as the library and as a texture: no blocking open.
    fifo(&d.join("lib.mtl"));
    obj(d, "lib.mtl");
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln"]);
    assert!(run.code == 0 && run.stderr.contains("not a regular file"), "{}", run.stderr);
    std::fs::remove_file(d.join("lib.mtl")).unwrap();
    fifo(&d.join("tex.png"));
    std::fs::write(d.join("lib.mtl"), "newmtl m\nKd 1 1 1\nKe 1 1 1\nmap_Kd tex.png\n").unwrap();
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln"]);
    assert!(run.code == 0 && run.stderr.contains("tex.png is not a regular file"), "{}", run.stderr);
    // A FIFO as the input itself: an I/O error (4).
    fifo(&d.join("pipe.obj"));
    let run = kiln(d, &["compile", "pipe.obj", "-o", "out.kiln"]);
    assert!(run.code == 4 && run.stderr.contains("not a regular file"), "{}", run.stderr);
}

#[test]
fn files_and_images_beyond_the_limits_are_refused_with_the_flag_to_raise() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    obj(d, "lib.mtl");
    std::fs::write(d.join("lib.mtl"), "newmtl m\nKd 1 1 1\nKe 1 1 1\nmap_Kd tex.png\n").unwrap();
    let img = image::RgbaImage::from_pixel(32, 16, image::Rgba([200, 100, 50, 255]));
    img.save(d.join("tex.png")).unwrap();
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln"]);
    assert!(run.code == 0 && !run.stderr.contains("tex.png"), "{}", run.stderr);
    // The image's header says 32 x 16: a 16-pixel side limit refuses it before decoding.
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln", "--max-image-side", "16"]);
    assert!(run.code == 0 && run.stderr.contains("32 x 16 pixels"), "{}", run.stderr);
    assert!(run.stderr.contains("--max-image-side"), "{}", run.stderr);
    // A file over the size limit: the input is an I/O error naming the flag.
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln", "--max-file-size", "20"]);
    assert!(run.code == 4 && run.stderr.contains("--max-file-size"), "{}", run.stderr);
}

#[test]
fn mtl_statements_without_their_numbers_are_warned_and_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    obj(d, "lib.mtl");
    // tobj panicked on `Kd 0.5 x`; a NaN colour rendered black; a negative emission is unphysical.
    std::fs::write(d.join("lib.mtl"), "newmtl m\nKd 0.5 x\nKs nan nan nan\nNs inf\nKe -1 2 3\n").unwrap();
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln", "--report", "r.json"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    for what in
        ["lib.mtl:2: `Kd 0.5 x` needs one or three finite numbers", "lib.mtl:3:", "lib.mtl:4:", "lib.mtl:5:"]
    {
        assert!(run.stderr.contains(what), "{what}: {}", run.stderr);
    }
    // The clamped emission is what the file holds: (0, 2, 3).
    let report = std::fs::read_to_string(d.join("r.json")).unwrap();
    assert!(report.contains("clamped to 0"), "{report}");
}

#[test]
#[cfg(unix)]
fn a_gltf_buffer_that_is_a_device_is_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let gltf = r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"/dev/zero","byteLength":36}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]}"#;
    std::fs::write(dir.path().join("dev.gltf"), gltf).unwrap();
    let run = kiln(dir.path(), &["compile", "dev.gltf", "-o", "out.kiln", "--allow-any-path"]);
    assert!(
        run.code == 1 && run.stderr.contains("/dev/zero is not a regular file"),
        "{}: {}",
        run.code,
        run.stderr
    );
}

#[test]
fn texture_paths_with_other_case_or_backslashes_are_found_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    obj(d, "lib.mtl");
    std::fs::create_dir(d.join("maps")).unwrap();
    let img = image::RgbaImage::from_pixel(8, 8, image::Rgba([200, 100, 50, 255]));
    img.save(d.join("maps").join("wall_skap.png")).unwrap();
    // Sponza's MTL names 00_SKAP.JPG for 00_skap.JPG; Windows exports write backslashes.
    std::fs::write(d.join("lib.mtl"), "newmtl m\nKd 1 1 1\nmap_Kd MAPS\\WALL_SKAP.PNG\n").unwrap();
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln", "--report", "r.json"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        run.stderr.contains("texture 'MAPS\\WALL_SKAP.PNG' is not there as written; using"),
        "{}",
        run.stderr
    );
    assert!(run.stderr.contains("maps/wall_skap.png"), "{}", run.stderr);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("r.json")).unwrap()).unwrap();
    assert_eq!(report["counts"]["textures"], 1, "the texture is in the file");
    assert!(!run.stderr.contains("cannot read"), "{}", run.stderr);
    // Two names that differ only in case: ambiguous, so the texture is not read (the
    // placeholder's warning says so).
    img.save(d.join("maps").join("Wall_Skap.png")).unwrap();
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(!run.stderr.contains("using") && run.stderr.contains("cannot read"), "{}", run.stderr);
}

/// Writes a glTF triangle at `d/name` whose buffer is the file `buffer` (a relative or absolute
/// URI) and whose base colour is the image `image`; the buffer's 36 bytes are written beside
/// the glTF as `tri.bin`.
fn gltf_naming(d: &Path, name: &str, buffer: &str, image: &str) {
    let bytes: Vec<u8> =
        [0f32, 0., 0., 1., 0., 0., 0., 1., 0.].iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(d.join("tri.bin"), bytes).unwrap();
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"{buffer}","byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
        "images":[{{"uri":"{image}"}}],"textures":[{{"source":0}}],
        "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}},"emissiveFactor":[1,1,1]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#
    );
    std::fs::write(d.join(name), gltf).unwrap();
}

#[test]
fn files_an_asset_names_outside_its_folder_are_refused_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let top = dir.path();
    let d = top.join("asset");
    std::fs::create_dir(&d).unwrap();
    let secret = top.join("secret.png");
    image::RgbaImage::from_pixel(4, 4, image::Rgba([9, 9, 9, 255])).save(&secret).unwrap();
    std::fs::create_dir(d.join("maps")).unwrap();
    image::RgbaImage::from_pixel(4, 4, image::Rgba([9, 9, 9, 255])).save(d.join("maps/in.png")).unwrap();
    gltf_naming(&d, "in.gltf", "./tri.bin", "maps/../maps/in.png");
    let run_in = |args: &[&str]| kiln(&d, args);
    let refused = |run: &Ended, reference: &str| {
        assert_eq!(run.code, 1, "{reference}: {}", run.stderr);
        assert!(
            run.stderr.contains(reference)
                && run.stderr.contains("outside the folders an asset may read from")
                && run.stderr.contains("--search-path")
                && run.stderr.contains("--allow-any-path"),
            "{reference}: {}",
            run.stderr
        );
        assert!(!Path::new(&d.join("out.kiln")).exists(), "nothing written");
    };
    // A glTF image by a relative path leading out, by an absolute path, and a buffer likewise.
    gltf_naming(&d, "up.gltf", "tri.bin", "../secret.png");
    refused(&run_in(&["compile", "up.gltf", "-o", "out.kiln"]), "image 0 ('../secret.png')");
    let abs = secret.display().to_string();
    gltf_naming(&d, "abs.gltf", "tri.bin", &abs);
    refused(&run_in(&["compile", "abs.gltf", "-o", "out.kiln"]), "image 0 (");
    gltf_naming(&d, "buf.gltf", "../../../../../../../../etc/passwd", "x.png");
    refused(&run_in(&["compile", "buf.gltf", "-o", "out.kiln"]), "buffer 0 (");
    // A file outside that does not exist is refused as outside, not reported missing.
    gltf_naming(&d, "gone.gltf", "tri.bin", "../nothing-here.png");
    refused(&run_in(&["compile", "gone.gltf", "-o", "out.kiln"]), "image 0 ('../nothing-here.png')");
    // OBJ: a texture and a material library leading out.
    std::fs::write(top.join("lib.mtl"), "newmtl m\nKd 1 1 1\nKe 1 1 1\n").unwrap();
    obj(&d, "../lib.mtl");
    refused(&run_in(&["compile", "scene.obj", "-o", "out.kiln"]), "material library '../lib.mtl'");
    obj(&d, "lib.mtl");
    std::fs::write(d.join("lib.mtl"), format!("newmtl m\nKd 1 1 1\nKe 1 1 1\nmap_Kd {abs}\n")).unwrap();
    refused(&run_in(&["compile", "scene.obj", "-o", "out.kiln"]), "texture '");
    // A link inside the folder leading out is refused too.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&secret, d.join("link.png")).unwrap();
        gltf_naming(&d, "link.gltf", "tri.bin", "link.png");
        refused(&run_in(&["compile", "link.gltf", "-o", "out.kiln"]), "image 0 ('link.png')");
    }
    // The sidecar's sky image likewise (a file named on the command line is always read).
    std::fs::write(d.join("sky.toml"), "[sky]\nimage = \"../sky.hdr\"\n").unwrap();
    refused(&run_in(&["compile", "in.gltf", "-c", "sky.toml", "-o", "out.kiln"]), "environment image");
    // Allowed: by --search-path naming the folder, or --allow-any-path; the depfile lists it.
    let run = run_in(&["compile", "up.gltf", "-o", "out.kiln", "--search-path", "..", "--depfile", "d.d"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let deps = std::fs::read_to_string(d.join("d.d")).unwrap();
    assert!(deps.contains("secret.png"), "{deps}");
    std::fs::remove_file(d.join("out.kiln")).unwrap();
    let run = run_in(&["compile", "scene.obj", "-o", "out.kiln", "--allow-any-path"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    // Files beside the asset and in its subfolders stay readable by default.
    let run = run_in(&["compile", "in.gltf", "-o", "in.kiln", "-W", "missing-setup=ignore"]);
    assert!(run.code == 0 && run.stderr.is_empty(), "{}", run.stderr);
    // An asset compiled through a path from elsewhere reads its own folder.
    let run = kiln(top, &["compile", "asset/in.gltf", "-o", "in2.kiln", "-W", "missing-setup=ignore"]);
    assert!(run.code == 0 && run.stderr.is_empty(), "{}", run.stderr);
    // A sandbox as Bazel makes one: real folders of links to the files. The asset's references
    // resolve beside its own real file, so they are read, and the bytes are the direct compile's.
    #[cfg(unix)]
    {
        let sb = top.join("sandbox/asset");
        std::fs::create_dir_all(sb.join("maps")).unwrap();
        for f in ["in.gltf", "tri.bin", "maps/in.png"] {
            std::os::unix::fs::symlink(d.join(f), sb.join(f)).unwrap();
        }
        let run = kiln(
            &top.join("sandbox"),
            &["compile", "asset/in.gltf", "-o", "sb.kiln", "-W", "missing-setup=ignore"],
        );
        assert!(run.code == 0 && run.stderr.is_empty(), "{}", run.stderr);
        let direct = std::fs::read(d.join("in.kiln")).unwrap();
        assert!(
            std::fs::read(top.join("sandbox/sb.kiln")).unwrap() == direct,
            "the sandboxed compile's bytes"
        );
        // But a link in the sandbox to a file outside the asset's real folder is still refused.
        for f in ["link.gltf", "link.png"] {
            std::os::unix::fs::symlink(d.join(f), sb.join(f)).unwrap();
        }
        std::fs::remove_file(d.join("out.kiln")).unwrap();
        let run = kiln(&sb, &["compile", "link.gltf", "-o", d.join("out.kiln").to_str().unwrap()]);
        refused(&run, "image 0 ('link.png')");
    }
}

/// A three-triangle OBJ in `d` and a sidecar `name.toml` holding `toml`.
fn tetra_with(d: &Path, name: &str, toml: &str) {
    std::fs::write(d.join("s.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\n")
        .unwrap();
    std::fs::write(d.join(format!("{name}.toml")), toml).unwrap();
}

#[test]
fn bake_settings_whose_product_exceeds_the_limits_are_refused_before_baking() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let spot = |i: usize| {
        format!(
            "[[light]]\nkind = \"spot\"\nposition = [0.{i}, 2, 0]\ndirection = [0, -1, 0]\nintensity = 1\n"
        )
    };
    let point = "[[light]]\nkind = \"point\"\nposition = [0, 2, 0]\nintensity = 1\n";
    let plan = |name: &str, extra: &[&str]| {
        let cfg = format!("{name}.toml");
        let mut args = vec!["plan", "s.obj", "-c", cfg.as_str(), "-W", "missing-setup=ignore"];
        args.extend_from_slice(extra);
        let start = Instant::now();
        let run = kiln(d, &args);
        assert!(start.elapsed() < Duration::from_secs(10), "{name}: {:?}", start.elapsed());
        run
    };
    let refused = |run: &Ended, parts: &[&str]| {
        assert_eq!(run.code, 2, "{}", run.stderr);
        for p in parts {
            assert!(run.stderr.contains(p), "{p:?} not in: {}", run.stderr);
        }
    };
    // 16 spot lights at 8192: 16 x 8192^2 depths of 4 bytes = 4096 MiB, each setting in range.
    let spots: String = (0..16).map(spot).collect();
    tetra_with(d, "spots", &format!("{spots}[bake]\nshadow_res = 8192\n"));
    let maps_mib = (16u64 * 8192 * 8192 * 4) >> 20;
    refused(
        &plan("spots", &[]),
        &[
            "16 shadow maps of 8192x8192",
            "--shadow-res 8192",
            &format!("{maps_mib} MiB"),
            "--max-bake-memory",
        ],
    );
    // Raised on the command line, the same settings plan.
    let run = plan("spots", &["--max-bake-memory", "5G", "--max-bake-rays", "2G"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    // A sidecar cannot raise its own limit.
    tetra_with(d, "raise", &format!("{spots}[bake]\nshadow_res = 8192\nmax_bake_memory = \"5G\"\n"));
    let run = plan("raise", &[]);
    assert!(run.code != 0 && run.stderr.contains("max_bake_memory"), "{}", run.stderr);
    // One medium at 512 cells a side for one light: 512^3 cells x 8 samples = 1073M rays (the
    // rays limit: its 128 MiB of volume is within the memory limit).
    tetra_with(
        d,
        "media",
        &format!("[[medium]]\nsigma_s = [0.1, 0.1, 0.1]\n{point}[bake]\nmedia_volume_res = 512\n"),
    );
    let rays = 512u64 * 512 * 512 * 8 / 1_000_000;
    refused(&plan("media", &[]), &["512x512x512 cells for 1 lights", &format!("{rays}M"), "--max-bake-rays"]);
    // A 1024^3 voxel grid (4 bytes a cell at least: 4 GiB) is refused before it is built.
    tetra_with(d, "vox", &format!("{point}[bake]\nvoxel_res = 1024\nshaft_res = 8\n"));
    refused(&plan("vox", &[]), &["a voxel grid of 1024x1024x1024 cells", "--voxel-res 1024"]);
    // The largest line-space budget does not lift the memory limit.
    tetra_with(d, "ls", &format!("{point}[bake]\nvoxel_res = 256\nline_space_budget = 1048576\n"));
    refused(&plan("ls", &[]), &["the line space at 256 cells", "--max-bake-memory"]);
    // The defaults plan.
    tetra_with(d, "plain", point);
    assert_eq!(plan("plain", &[]).code, 0);
}

#[test]
fn a_face_of_100000_corners_compiles_quickly_into_triangles_that_tile_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A regular polygon of n corners, counter-clockwise seen from +z, in one face.
    let n = 100_000usize;
    let mut text = String::new();
    let corners: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [a.cos(), a.sin()]
        })
        .collect();
    for c in &corners {
        text.push_str(&format!("v {:.7} {:.7} 0\n", c[0], c[1]));
    }
    text.push('f');
    for i in 1..=n {
        text.push_str(&format!(" {i}"));
    }
    text.push('\n');
    std::fs::write(d.join("disc.obj"), text).unwrap();
    let start = Instant::now();
    let run = kiln(
        d,
        &["compile", "disc.obj", "-o", "disc.kiln", "-W", "missing-setup=ignore", "-W", "data-loss=ignore"],
    );
    let took = start.elapsed();
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(took < Duration::from_secs(10), "{took:?}");
    let file = kiln_format::KilnFile::open(&d.join("disc.kiln"), kiln_format::Checksums::Eager).unwrap();
    let view = kiln_format::SceneView::new(&file).unwrap();
    // The triangles tile the polygon: their areas sum to its area (the shoelace formula over the
    // corners as written), every one wound as the face (+z), none beyond n - 2.
    let shoelace: f64 = (0..n)
        .map(|i| {
            let (p, q) = (corners[i], corners[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
        / 2.0;
    let mut area = 0.0;
    for t in view.triangles {
        let p = t.map(|i| view.vertices[i as usize].position.map(f64::from));
        let signed =
            ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1])) / 2.0;
        // (Near-collinear neighbours, rounded to f32, may come out a rounding error below zero.)
        assert!(signed > -1e-9, "a triangle wound against the face: {signed}");
        area += signed;
    }
    assert!(view.triangles.len() <= n - 2);
    assert!((area - shoelace).abs() < 1e-4 * shoelace, "triangles {area}, polygon {shoelace}");
}

#[test]
fn sidecar_material_values_outside_what_a_material_can_be_are_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    obj(d, "lib.mtl");
    std::fs::write(d.join("lib.mtl"), "newmtl m\nKd 0.5 0.5 0.5\nKe 1 1 1\n").unwrap();
    for (line, field, value) in [
        ("metallic = 2.0", "metallic", "2"),
        ("roughness = -0.1", "roughness", "-0.1"),
        ("base_color = [1.5, 0.2, 0.2]", "base_color", "1.5"),
        ("base_color = [0.5, nan, 0.2]", "base_color", "NaN"),
        ("emission = [-1.0, 0.0, 0.0]", "emission", "-1"),
        ("emission = [inf, 0.0, 0.0]", "emission", "inf"),
    ] {
        std::fs::write(d.join("s.toml"), format!("[material.\"m\"]\n{line}\n")).unwrap();
        let run = kiln(d, &["compile", "scene.obj", "-c", "s.toml", "-o", "out.kiln"]);
        assert_eq!(run.code, 1, "{line}: {}", run.stderr);
        assert!(
            run.stderr.contains("material \"m\"") && run.stderr.contains(&format!("{field} holds {value}")),
            "{line}: {}",
            run.stderr
        );
    }
    // Within range: compiles.
    std::fs::write(
        d.join("s.toml"),
        "[material.\"m\"]\nbase_color = [1.0, 0.0, 0.5]\nmetallic = 1.0\nroughness = 0.0\n",
    )
    .unwrap();
    assert_eq!(kiln(d, &["compile", "scene.obj", "-c", "s.toml", "-o", "out.kiln"]).code, 0);
}

#[test]
fn usemtl_of_a_material_no_library_defines_is_a_warning_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("scene.obj"),
        "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\nusemtl missing\nf 1 3 2\n",
    )
    .unwrap();
    std::fs::write(d.join("lib.mtl"), "newmtl m\nKd 0.5 0.5 0.5\nKe 1 1 1\n").unwrap();
    let run = kiln(d, &["compile", "scene.obj", "-o", "out.kiln", "-W", "missing-setup=ignore"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        run.stderr.contains("scene.obj:7: usemtl 'missing' names no material of lib.mtl")
            && !run.stderr.contains("'m'"),
        "{}",
        run.stderr
    );
    // --strict fails it (a data-loss warning).
    assert_eq!(kiln(d, &["compile", "scene.obj", "-o", "out.kiln", "--strict"]).code, 1);
}
