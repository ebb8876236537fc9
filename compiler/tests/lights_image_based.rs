//! glTF `EXT_lights_image_based`: the image-based light a scene references becomes its
//! environment. Every expected value is computed here from the extension's text and the
//! environment map's documented mapping (docs/sidecar.md, "Environment"), not by kiln's code: the
//! cube-map face table (OpenGL 4.6, table 8.19), the z negation that reads that left-handed table
//! in glTF's right-handed frame, the faces' vertical flip, RGBD and the 2.2 power, and the
//! rotation as an axis-angle turn written out by hand.

#[allow(dead_code)] // Its GLB and texture helpers serve other tests.
#[path = "util/gltf.rs"]
mod gltf_builder;
#[path = "util/run.rs"]
mod run;

use std::path::{Path, PathBuf};

use gltf_builder::Gltf;
use kiln_compiler::import::import;
use kiln_compiler::ir::{EnvironmentImage, Scene};
use serde_json::json;

/// Six flat face colours (sRGB-style 8-bit values), +X, −X, +Y, −Y, +Z, −Z: distinct, and within
/// a factor of 64 in luminance of each other (no sun is taken out of the map).
const FLAT: [[u8; 3]; 6] =
    [[200, 40, 40], [40, 200, 40], [40, 40, 200], [200, 200, 40], [40, 200, 200], [200, 40, 200]];

/// An 8-bit value as the extension's writers encode it: c^(1/2.2), so c = (v / 255)^2.2.
fn decode(v: u8) -> f64 {
    (f64::from(v) / 255.0).powf(2.2)
}

fn rgb(c: [u8; 3]) -> [f64; 3] {
    c.map(decode)
}

/// PNG bytes of an RGB image whose pixel (x, y) (y from the top) is `f(x, y)`.
fn png_rgb(n: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let img = image::RgbImage::from_fn(n, n, |x, y| image::Rgb(f(x, y)));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// PNG bytes of a flat `w` × `h` RGBA image (alpha: RGBD's divisor).
fn png_rgba(w: u32, h: u32, c: [u8; 4]) -> Vec<u8> {
    let img = image::RgbaImage::from_pixel(w, h, image::Rgba(c));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// The six flat faces, 4 × 4 pixels.
fn flat_faces() -> [Vec<u8>; 6] {
    std::array::from_fn(|k| png_rgb(4, |_, _| FLAT[k]))
}

/// A one-quad glTF in `dir` whose scene references light 0 of `EXT_lights_image_based`, with
/// `faces` as its mip 0: faces 0, 2 and 4 in buffer views, 1, 3 and 5 as files beside it (both
/// ways the importer finds images). `light` is merged into the light's object.
fn ibl_gltf(dir: &Path, name: &str, faces: &[Vec<u8>; 6], light: serde_json::Value) -> Gltf {
    let mut g = Gltf::quad();
    let mut images = Vec::new();
    for (k, bytes) in faces.iter().enumerate() {
        if k % 2 == 0 {
            let view = g.view(bytes, None);
            images.push(json!({"bufferView": view, "mimeType": "image/png"}));
        } else {
            let file = format!("{name}_face{k}.png");
            std::fs::write(dir.join(&file), bytes).unwrap();
            images.push(json!({ "uri": file }));
        }
    }
    g.json["images"] = json!(images);
    let mut l = json!({
        "name": "room",
        "irradianceCoefficients": vec![[0.0; 3]; 9],
        "specularImageSize": 4,
        "specularImages": [[0, 1, 2, 3, 4, 5]],
    });
    for (k, v) in light.as_object().unwrap() {
        l[k] = v.clone();
    }
    g.json["extensionsUsed"] = json!(["EXT_lights_image_based"]);
    g.json["extensions"] = json!({"EXT_lights_image_based": {"lights": [l]}});
    g.json["scenes"][0]["extensions"] = json!({"EXT_lights_image_based": {"light": 0}});
    g
}

fn write(dir: &Path, name: &str, faces: &[Vec<u8>; 6], light: serde_json::Value) -> PathBuf {
    ibl_gltf(dir, name, faces, light).write(dir, name)
}

/// The direction at the centre of texel (x, y) of a `w` × `h` map, by docs/sidecar.md: row 0 the
/// zenith, the centre column along +z, the left and right edges along −z, u growing towards +x
/// (a quarter of the way across looks along +x).
fn texel_direction(x: u32, y: u32, w: u32, h: u32) -> [f64; 3] {
    let phi = std::f64::consts::TAU * (f64::from(x) + 0.5) / f64::from(w);
    let theta = std::f64::consts::PI * (f64::from(y) + 0.5) / f64::from(h);
    [theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos()]
}

/// `d` turned by `degrees` about +y by the right-hand rule (+90 carries +z to +x).
fn turn_about_y(d: [f64; 3], degrees: f64) -> [f64; 3] {
    let (s, c) = degrees.to_radians().sin_cos();
    [c * d[0] + s * d[2], d[1], -s * d[0] + c * d[2]]
}

/// The face (0..6: +X, −X, +Y, −Y, +Z, −Z) that world direction `d` sees in a light turned by
/// `degrees` about +y, or `None` within 1 % of a face edge. The light's rotation carries its own
/// frame into the world, so `d` looks along the light's `turn(d, −degrees)`; the cube's table is
/// left-handed, so its z is glTF's negated.
fn expected_face(d: [f64; 3], degrees: f64) -> Option<usize> {
    let l = turn_about_y(d, -degrees);
    let c = [l[0], l[1], -l[2]];
    let a = c.map(f64::abs);
    let axis = (0..3).max_by(|&i, &j| a[i].total_cmp(&a[j])).unwrap();
    let second = (0..3).filter(|&i| i != axis).map(|i| a[i]).fold(0.0, f64::max);
    (a[axis] > 1.01 * second).then_some(2 * axis + usize::from(c[axis] < 0.0))
}

fn environment(s: &Scene) -> &EnvironmentImage {
    s.environment.as_ref().unwrap_or_else(|| panic!("no environment; warnings: {:#?}", s.warnings))
}

/// Checks every texel of `env` away from face edges against `colours[face]` × `scale`; returns
/// how many texels each face gave.
fn check_flat(env: &EnvironmentImage, colours: &[[f64; 3]; 6], scale: f64, degrees: f64) -> [usize; 6] {
    let mut seen = [0; 6];
    for y in 0..env.height {
        for x in 0..env.width {
            let d = texel_direction(x, y, env.width, env.height);
            let Some(face) = expected_face(d, degrees) else { continue };
            seen[face] += 1;
            let got = env.pixels[(y * env.width + x) as usize];
            for ch in 0..3 {
                let want = colours[face][ch] * scale;
                assert!(
                    (f64::from(got[ch]) - want).abs() <= 1e-5 * want.max(1.0),
                    "texel ({x}, {y}) looking along {d:?}: got {got:?}, want face {face}'s {:?} x {scale}",
                    colours[face]
                );
            }
        }
    }
    seen
}

/// Each face shows its colour where the extension's conventions put it: ±X and ±Y along the
/// world's ±x and ±y, the cube's +Z face along the world's −z (the table's z negated: what a glTF
/// camera, looking along −z, sees ahead) and −Z behind; the map is four face widths wide, the
/// faces read from buffer views and files alike; the name says where it came from.
#[test]
fn each_face_lies_where_the_extension_puts_it() {
    let d = tempfile::tempdir().unwrap();
    let s = import(&write(d.path(), "flat", &flat_faces(), json!({}))).unwrap();
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let env = environment(&s);
    assert_eq!((env.width, env.height, env.rotation_degrees), (16, 8, 0.0));
    assert!(env.name.contains("EXT_lights_image_based light 0 'room'"), "{}", env.name);
    let seen = check_flat(env, &FLAT.map(rgb), 1.0, 0.0);
    assert!(seen.iter().all(|&n| n > 0), "every face seen: {seen:?}");
    // Spelled out for one texel: the centre column (along +z) at the horizon shows face −Z.
    let p = env.pixels[(4 * 16 + 8) as usize];
    assert!(
        (f64::from(p[2]) - decode(200)).abs() < 1e-6 && (f64::from(p[1]) - decode(40)).abs() < 1e-6,
        "{p:?}"
    );
}

/// `rotation` turns the light into the world: turned 90° about +y, what it showed along +z (face
/// −Z) is seen along +x, and what it showed along −x (face −X) along +z. `intensity` scales.
#[test]
fn rotation_and_intensity_place_and_scale_the_light() {
    let d = tempfile::tempdir().unwrap();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let light = json!({"rotation": [0.0, h, 0.0, h], "intensity": 2.5});
    let s = import(&write(d.path(), "turned", &flat_faces(), light)).unwrap();
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let env = environment(&s);
    let seen = check_flat(env, &FLAT.map(rgb), 2.5, 90.0);
    assert!(seen.iter().all(|&n| n > 0), "every face seen: {seen:?}");
    assert_eq!(expected_face([1.0, 0.0, 0.0], 90.0), Some(5));
    assert_eq!(expected_face([0.0, 0.0, 1.0], 90.0), Some(1));
}

/// Within a face: the image's top row is the table's t = 1 (the extension's flip for glTF's
/// texture space), its left column s = 0. Face +X is split into a top and a bottom half, face +Z
/// (seen along −z) into a left and a right half, 8 × 8 pixels each.
#[test]
fn faces_are_read_flipped_as_the_extension_says() {
    let d = tempfile::tempdir().unwrap();
    let (a, b) = ([220u8, 30, 30], [30, 30, 220]);
    let mut faces = flat_faces().map(|_| png_rgb(8, |_, _| [90, 90, 90]));
    faces[0] = png_rgb(8, |_, y| if y < 4 { a } else { b });
    faces[4] = png_rgb(8, |x, _| if x < 4 { a } else { b });
    let s = import(&write(d.path(), "split", &faces, json!({"specularImageSize": 8}))).unwrap();
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let env = environment(&s);
    assert_eq!((env.width, env.height), (32, 16));
    let at = |d: [f64; 3]| {
        let u = d[0].atan2(-d[2]).rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU;
        let v = (d[1] / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()).acos() / std::f64::consts::PI;
        let (x, y) = ((u * 32.0) as u32, (v * 16.0) as u32);
        env.pixels[(y * 32 + x) as usize].map(f64::from)
    };
    let close = |p: [f64; 3], c: [u8; 3]| p.iter().zip(rgb(c)).all(|(p, c)| (p - c).abs() < 1e-6);
    // +X face: sc = −z, tc = −y; below the horizon tc > 0, t > ½: the image's top half.
    assert!(close(at([1.0, -0.6, 0.1]), a), "{:?}", at([1.0, -0.6, 0.1]));
    assert!(close(at([1.0, 0.6, 0.1]), b), "{:?}", at([1.0, 0.6, 0.1]));
    // +Z face, seen along the world's −z: sc = +x of the cube (the world's x); to the left of a
    // camera looking along −z (world x < 0) s < ½: the image's left half (not mirrored).
    assert!(close(at([-0.6, 0.1, -1.0]), a), "{:?}", at([-0.6, 0.1, -1.0]));
    assert!(close(at([0.6, 0.1, -1.0]), b), "{:?}", at([0.6, 0.1, -1.0]));
}

/// A PNG with alpha holds RGBD: (c / 255)^2.2 / (alpha / 255), beyond 1 where alpha is low.
#[test]
fn a_png_with_alpha_is_rgbd() {
    let d = tempfile::tempdir().unwrap();
    let mut faces = flat_faces();
    faces[2] = png_rgba(4, 4, [200, 180, 160, 64]);
    let s = import(&write(d.path(), "rgbd", &faces, json!({}))).unwrap();
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    let mut colours = FLAT.map(rgb);
    colours[2] = [200, 180, 160].map(|c| decode(c) / (64.0 / 255.0));
    assert!(colours[2][0] > 2.0);
    check_flat(environment(&s), &colours, 1.0, 0.0);
}

/// A bad-payload case: a name, what breaks the file, what the one warning says, and whether the
/// light is kept (a repaired field) or ignored.
type Case = (&'static str, Box<dyn Fn(&mut Gltf)>, &'static str, bool);

/// What kiln cannot use in the extension is warned about, naming the file and the fault, and
/// never fails the import: the light is ignored, or (a rotation) the field repaired.
#[test]
fn bad_payloads_warn_and_the_import_succeeds() {
    let d = tempfile::tempdir().unwrap();
    let faces = flat_faces();
    let cases: Vec<Case> = vec![
        (
            "index",
            Box::new(|g| {
                g.json["extensions"]["EXT_lights_image_based"]["lights"][0]["specularImages"] =
                    json!([[0, 1, 2, 3, 4, 7]])
            }),
            "the -Z face (specularImages[0][5]) is 7, not one of the file's 6 images",
            false,
        ),
        (
            "sizes",
            Box::new(|g| {
                let big = png_rgb(8, |_, _| FLAT[2]);
                let v = g.view(&big, None);
                g.json["images"][2] = json!({"bufferView": v, "mimeType": "image/png"});
            }),
            "is 8 x 8 pixels but the +X face 4 x 4: the faces differ in size",
            false,
        ),
        (
            "oblong",
            Box::new(|g| {
                let v = g.view(&png_rgba(4, 2, [9, 9, 9, 255]), None);
                g.json["images"][0] = json!({"bufferView": v, "mimeType": "image/png"});
            }),
            "the +X face (specularImages[0][0]), image 0 is 4 x 2 pixels: a cube face is square, not empty",
            false,
        ),
        (
            "garbled",
            Box::new(|g| {
                let v = g.view(b"not an image at all", None);
                g.json["images"][4] = json!({"bufferView": v, "mimeType": "image/png"});
            }),
            "the +Z face (specularImages[0][4]), image 4: cannot decode",
            false,
        ),
        (
            "nolight",
            Box::new(|g| g.json["scenes"][0]["extensions"]["EXT_lights_image_based"]["light"] = json!(3)),
            "scene 0 names light 3, but the file defines 1",
            false,
        ),
        (
            "dark",
            Box::new(|g| {
                g.json["extensions"]["EXT_lights_image_based"]["lights"][0]["intensity"] = json!(-1.0)
            }),
            "intensity -1.0 is not a finite number ≥ 0",
            false,
        ),
        (
            "fivefaces",
            Box::new(|g| {
                g.json["extensions"]["EXT_lights_image_based"]["lights"][0]["specularImages"] =
                    json!([[0, 1, 2, 3, 4]])
            }),
            "specularImages[0] is not six image indices",
            false,
        ),
        (
            "long",
            Box::new(|g| {
                g.json["extensions"]["EXT_lights_image_based"]["lights"][0]["rotation"] =
                    json!([0.0, 0.0, 0.0, 2.0])
            }),
            "rotation [0.0,0.0,0.0,2.0] has length 2.000000, not 1 (a rotation is a unit quaternion); normalised",
            true,
        ),
        (
            "zero",
            Box::new(|g| {
                g.json["extensions"]["EXT_lights_image_based"]["lights"][0]["rotation"] = json!([0, 0, 0, 0])
            }),
            "rotation [0,0,0,0] has length 0, no rotation; the identity is used",
            true,
        ),
        (
            "size",
            Box::new(|g| {
                g.json["extensions"]["EXT_lights_image_based"]["lights"][0]["specularImageSize"] = json!(256)
            }),
            "specularImageSize 256 is not the 4 pixels of mip 0's faces; the images' size is used",
            true,
        ),
    ];
    for (name, break_it, says, kept) in cases {
        let mut g = ibl_gltf(d.path(), name, &faces, json!({}));
        break_it(&mut g);
        let path = g.write(d.path(), name);
        let s = import(&path).unwrap_or_else(|e| panic!("{name}: the import failed: {e:?}"));
        let file = path.display().to_string();
        let hits: Vec<_> =
            s.warnings.iter().filter(|w| w.message.contains(says) && w.message.contains(&file)).collect();
        assert_eq!(
            hits.len(),
            1,
            "{name}: one warning naming the file and saying {says:?}: {:#?}",
            s.warnings
        );
        assert_eq!(s.warnings.len(), 1, "{name}: {:#?}", s.warnings);
        assert_eq!(s.environment.is_some(), kept, "{name}: {:#?}", s.warnings);
        if kept {
            // Repaired rotations are the identity here: the faces where they were.
            check_flat(environment(&s), &FLAT.map(rgb), 1.0, 0.0);
        } else {
            assert!(hits[0].message.contains("the light is ignored"), "{name}: {}", hits[0].message);
        }
        if ["index", "sizes"].contains(&name) {
            // And the whole compile, through the command line.
            let out = format!("{name}.kiln");
            let gltf = format!("{name}.gltf");
            let mut args = vec!["compile", gltf.as_str(), "-o", out.as_str()];
            args.extend(QUICK);
            run::kiln(d.path(), &args).expect(0).says(says);
            assert!(d.path().join(&out).is_file());
        }
    }
}

/// Compile options that keep a one-quad compile quick.
const QUICK: [&str; 6] = ["--probes", "off", "--shaft-variants", "none", "--environment-res", "64"];

/// The irradiance coefficients are not read (kiln projects its own from the map): nothing in them
/// can fail or change the import. Nor can the further mips, which kiln prefilters itself.
#[test]
fn irradiance_coefficients_and_further_mips_are_not_read() {
    let d = tempfile::tempdir().unwrap();
    let light = json!({"irradianceCoefficients": "not even an array", "specularImages": [[0, 1, 2, 3, 4, 5], "junk", [99]]});
    let s = import(&write(d.path(), "sh", &flat_faces(), light)).unwrap();
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
    check_flat(environment(&s), &FLAT.map(rgb), 1.0, 0.0);
}

/// The command line and the sidecar win over the file's light, with a warning that says so; the
/// plan names the environment's source. A file that requires the extension compiles.
#[test]
fn a_sidecar_or_the_command_line_replaces_the_files_light() {
    let d = tempfile::tempdir().unwrap();
    let mut g = ibl_gltf(d.path(), "cli", &flat_faces(), json!({}));
    g.json["extensionsRequired"] = json!(["EXT_lights_image_based"]);
    g.write(d.path(), "cli");
    let plan = run::kiln(d.path(), &["plan", "cli.gltf"]);
    plan.expect(0);
    assert!(plan.stdout.contains("cli.gltf: EXT_lights_image_based light 0 'room' (16x8)"), "{plan:#?}");
    assert!(!plan.stderr.contains("not supported"), "{plan:#?}");
    let mut args = vec!["compile", "cli.gltf", "-o", "cli.kiln"];
    args.extend(QUICK);
    run::kiln(d.path(), &args).expect(0);
    let inspect = run::kiln(d.path(), &["inspect", "cli.kiln"]);
    // The map keeps its 16 texels (narrower than --environment-res); the face files are inputs.
    assert!(inspect.expect(0).stdout.contains("environment 16x8"), "{inspect:#?}");
    assert!(inspect.stdout.contains("cli_face1.png, cli_face3.png, cli_face5.png"), "{inspect:#?}");
    let plan = run::kiln(d.path(), &["plan", "cli.gltf", "--environment", "studio"]);
    plan.expect(0).says(
        "--environment: the sky given here (studio) replaces the asset's environment, cli.gltf: \
         EXT_lights_image_based light 0 'room'",
    );
    assert!(plan.stdout.contains("studio (1024x512)"), "{plan:#?}");
    // Faces finer than the map may be (four faces wide, at most --max-image-side) are averaged
    // down first: 8-pixel faces under a 16-pixel limit make a 16 x 8 map.
    let fine: [Vec<u8>; 6] = std::array::from_fn(|k| png_rgb(8, |_, _| FLAT[k]));
    ibl_gltf(d.path(), "fine", &fine, json!({"specularImageSize": 8})).write(d.path(), "fine");
    let plan = run::kiln(d.path(), &["plan", "fine.gltf"]);
    assert!(plan.expect(0).stdout.contains("'room' (32x16)"), "{plan:#?}");
    let plan = run::kiln(d.path(), &["plan", "fine.gltf", "--max-image-side", "16"]);
    assert!(plan.expect(0).stdout.contains("'room' (16x8)"), "{plan:#?}");
    std::fs::write(d.path().join("sky.toml"), "[sky]\nradiance = [0.5, 0.5, 0.5]\n").unwrap();
    let plan = run::kiln(d.path(), &["plan", "cli.gltf", "-c", "sky.toml"]);
    plan.expect(0)
        .says("sky.toml: the sky given here ([sky], a constant sky) replaces the asset's environment");
    assert!(plan.stdout.contains("no environment"), "{plan:#?}");
    std::fs::write(d.path().join("studio.toml"), "[sky]\nmodel = \"studio\"\n").unwrap();
    let plan = run::kiln(d.path(), &["plan", "cli.gltf", "-c", "studio.toml", "--strict"]);
    // `--strict` fails on it: the file is not what the asset says.
    plan.expect(1).says("studio.toml: the sky given here (studio) replaces the asset's environment");
}
