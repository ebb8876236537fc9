//! kiln's reference path tracer (`kiln-play --reference`) against Mitsuba 3, an independent
//! renderer: scenes rendered by both from the same geometry, materials, lights and camera,
//! compared with HDR-FLIP and relative MSE.
//!
//! The cases cover both kinds of emitter kiln's next-event estimation handles (the demo box with
//! its analytic rect light, and the same box with the light replaced by an emissive quad), vertex
//! colours, fog, an environment map, and glTF's glossy BSDF (metal, a dielectric with a coloured
//! F0, a clear coat): Mitsuba renders that through `tests/mitsuba/gltf_bsdf.py`, a Python plugin
//! written from the definitions. Mitsuba renders many more samples per pixel than kiln and serves
//! as the reference; the mean HDR-FLIP of kiln's image against it must be at most 0.05, or, where
//! Mitsuba's own image at kiln's sample count (another seed, printed as the noise floor) is
//! further off than that, within 15 % of that noise. An unbiased kiln comes close to it.
//!
//! The scene goes to Mitsuba as JSON (`tests/mitsuba/render.py` documents the mapping of
//! kiln's conventions onto Mitsuba's), rendered on the CPU by the `llvm_ad_rgb` variant. The
//! comparison runs in the same script with `flip_evaluator`, the FLIP authors' implementation.
//!
//! Needs a Vulkan device and a Python with `mitsuba`, `flip-evaluator` and `numpy`: the virtual
//! environment `.venv-mitsuba` at the workspace root, or the interpreter `KILN_MITSUBA_PYTHON`
//! names. Without either the tests say why and pass, unless `KILN_REQUIRE_VULKAN` or
//! `KILN_REQUIRE_MITSUBA` is set (as `.ci/run` does), when they fail. `KILN_MITSUBA_OUT=DIR`
//! keeps the scene and both images (`.npy`, linear RGB) there.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use std::time::Instant;

use glam::Vec3;
use kiln_compiler::import::demo::{cornell_box, lambert_material};
use kiln_compiler::ir::{Material, Scene};
use kiln_compiler::settings::{Settings, TextureFormat};
use kiln_format::manifest::{Bounds, LightKind, Medium, Wrap};
use kiln_format::sections::{GpuMaterial, MaterialFlags, NO_TEXTURE, Vertex};
use kiln_test_support::{gpu_test, mitsuba_python, read_npy, require, workspace, write_npy, write_npy_rgba8};
use kiln_tests::{Options, compile};

/// Image size: small, as kiln samples about 0.06 M paths/s on lavapipe with two cores.
const W: u32 = 64;
const H: u32 = 48;
/// kiln's samples per pixel (about 20 s per case on lavapipe with two cores; 512 took 45 s, and
/// the suite past CI's 30 minutes).
const KILN_SPP: u32 = 256;
/// kiln's samples per pixel in fog, where a path has more vertices and more noise.
const KILN_SPP_FOG: u32 = 512;
/// Mitsuba's, for the reference (about 1.4 M paths/s on two cores): at 8192 its own noise is
/// small beside kiln's (measured against 65536 spp: mean FLIP 0.011 at 16384 spp, 0.034 at 512).
const MITSUBA_SPP: u32 = 8192;
/// The bound on mean HDR-FLIP of kiln's image against Mitsuba's.
const MAX_MEAN_FLIP: f64 = 0.05;

/// kiln's mean FLIP against Mitsuba's reference may exceed `MAX_MEAN_FLIP` only up to this
/// multiple of Mitsuba's own at kiln's sample count (another seed).
const NOISE_MARGIN: f64 = 1.15;
/// The image's mean radiance against Mitsuba's, per channel: within 3 %. The mean of 3,072
/// pixels is steady where a pixel is noisy (its spread at 256 spp is ~0.1 %), so a lost or
/// doubled share of the light fails here even where FLIP's noise floor would hide it.
const MAX_MEAN_RATIO_ERROR: f64 = 0.03;

/// The renderers take turns, so that each has the machine's cores and its time is its own.
static MACHINE: Mutex<()> = Mutex::new(());

/// The scene as `render.py` reads it: camera, triangles grouped by material, rect lights.
/// Textures go beside it as `.npy` files of RGBA8 texels, named by `at`.
fn scene_json(s: &Scene, env_npy: Option<&Path>, at: &dyn Fn(&str) -> PathBuf) -> String {
    let list = |v: &mut dyn Iterator<Item = String>| v.collect::<Vec<_>>().join(",");
    let num = |x: f32| {
        assert!(x.is_finite());
        format!("{x}")
    };
    let vec3 = |v: [f32; 3]| format!("[{}]", list(&mut v.iter().map(|&x| num(x))));
    assert!(
        s.environment.is_some() || s.sky.radiance == [0.0; 3],
        "the Mitsuba scene has no constant sky (an environment instead)"
    );
    let cam = &s.cameras[0];
    let texture_npy = |t: u32| {
        let tex = &s.textures[t as usize];
        let path = at(&format!("texture{t}.npy"));
        write_npy_rgba8(&path, tex.width, tex.height, &tex.rgba);
        format!("{:?}", path.display().to_string())
    };
    let mut meshes = Vec::new();
    for (m, material) in s.materials.iter().enumerate() {
        let g = &material.gpu;
        let lambertian = g.flags & MaterialFlags::DIFFUSE_ONLY != 0;
        assert!(
            !lambertian || g.textures().iter().all(|&t| t == NO_TEXTURE),
            "{}: only untextured Lambertian materials map onto Mitsuba's diffuse here",
            material.name
        );
        if g.emission != [0.0; 3] && g.flags & MaterialFlags::DOUBLE_SIDED != 0 {
            // ToyCar's body: its back faces (inside the closed body) emit in kiln only.
            eprintln!("{}: double-sided emission; Mitsuba's area emitters are one-sided", material.name);
        }
        // Coverage (alpha blending, which kiln's reference reads as the probability of meeting
        // the surface): only untextured coverage maps onto Mitsuba's `mask`, and none at all is
        // no surface.
        let blend = g.alpha_mode() == Some(kiln_format::sections::AlphaMode::Blend);
        let coverage = if blend { g.base_color[3] } else { 1.0 };
        if coverage == 0.0 {
            continue;
        }
        assert!(
            !blend || g.base_color_texture == NO_TEXTURE || coverage == 1.0 || s.colors.is_empty(),
            "{}: textured coverage is not mapped onto Mitsuba here",
            material.name
        );
        let textured = g.textures().iter().any(|&t| t != NO_TEXTURE);
        let mut remap = vec![u32::MAX; s.vertices.len()];
        let (mut positions, mut triangles, mut colors) = (Vec::new(), Vec::new(), Vec::new());
        let (mut normals, mut uvs) = (Vec::new(), Vec::new());
        for (t, _) in s.triangles.iter().zip(&s.triangle_materials).filter(|(_, tm)| **tm as usize == m) {
            for &i in t {
                if remap[i as usize] == u32::MAX {
                    remap[i as usize] = (positions.len() / 3) as u32;
                    let v = &s.vertices[i as usize];
                    positions.extend(v.position);
                    normals.extend(v.normal);
                    // Vertex colours (unorm16) as Mitsuba reads them: linear floats.
                    if let Some(c) = s.colors.get(i as usize) {
                        colors.extend(c[..3].iter().map(|&v| v as f32 / 65535.0));
                    }
                    if textured {
                        uvs.extend(s.uvs[i as usize]);
                    }
                }
                triangles.push(remap[i as usize]);
            }
        }
        if triangles.is_empty() {
            continue;
        }
        let b = g.base_color;
        // Lambertian materials become Mitsuba's `diffuse`; the others glTF's BSDF
        // (`tests/mitsuba/gltf_bsdf.py`), given its parameters.
        let glossy = if lambertian {
            String::new()
        } else {
            let (f0, f90) = g.dielectric();
            // Textures by the plugin's names; a texture's wrap and filter are its sampler's.
            let slots = [
                ("base_tex", g.base_color_texture),
                ("metallic_roughness_tex", g.metallic_roughness_texture),
                ("normal_tex", g.normal_texture),
                ("clearcoat_tex", g.clearcoat_texture),
                ("clearcoat_roughness_tex", g.clearcoat_roughness_texture),
                ("transmission_tex", g.transmission_texture),
            ];
            let mut textures = String::new();
            for (name, t) in slots.into_iter().filter(|&(_, t)| t != NO_TEXTURE) {
                let tex = &s.textures[t as usize];
                assert_eq!(tex.wrap_u, tex.wrap_v, "{}: one wrap mode for both axes", material.name);
                let wrap = match tex.wrap_u {
                    Wrap::Repeat => "repeat",
                    Wrap::MirroredRepeat => "mirror",
                    Wrap::ClampToEdge => "clamp",
                };
                let _ = write!(
                    textures,
                    r#","{name}":{},"wrap":"{wrap}","linear":{}"#,
                    texture_npy(t),
                    tex.mag_linear
                );
            }
            format!(
                r#","material":{{"base_r":{},"base_g":{},"base_b":{},"metallic":{},"roughness":{},"f0_r":{},"f0_g":{},"f0_b":{},"f90":{},"clearcoat":{},"clearcoat_roughness":{},"transmission":{},"normal_scale":{}{textures}}},"coverage":{}"#,
                num(b[0]),
                num(b[1]),
                num(b[2]),
                num(g.metallic),
                num(g.roughness),
                num(f0[0]),
                num(f0[1]),
                num(f0[2]),
                num(f90),
                num(g.clearcoat),
                num(g.clearcoat_roughness),
                num(g.transmission),
                num(g.normal_scale),
                num(coverage),
            )
        };
        let emission_texture = match g.emissive_texture {
            t if t == NO_TEXTURE || g.emission == [0.0; 3] => String::new(),
            t => format!(r#","emission_tex":{}"#, texture_npy(t)),
        };
        // Vertex normals and texture coordinates for glossy materials (the Lambertian test
        // scenes have flat faces, which Mitsuba's face normals give).
        let per_vertex = if lambertian {
            String::new()
        } else {
            format!(
                r#","normals":[{}],"uvs":[{}]"#,
                list(&mut normals.iter().map(|&x| num(x))),
                list(&mut uvs.iter().map(|&x| num(x)))
            )
        };
        meshes.push(format!(
            r#"{{"name":"{}","albedo":{},"emission":{},"positions":[{}],"triangles":[{}],"colors":[{}]{glossy}{emission_texture}{per_vertex}}}"#,
            material.name,
            vec3([b[0], b[1], b[2]]),
            vec3(g.emission),
            list(&mut positions.iter().map(|&x| num(x))),
            list(&mut triangles.iter().map(u32::to_string)),
            list(&mut colors.iter().map(|&x| num(x))),
        ));
    }
    let (mut rects, mut points) = (Vec::new(), Vec::new());
    for l in &s.lights {
        assert!(l.range == 0.0, "light {}: a range has no Mitsuba equivalent", l.name);
        // A point light of intensity I (W/sr per channel) is Mitsuba's `point` emitter.
        if matches!(l.kind, LightKind::Point) {
            points.push(format!(
                r#"{{"position":{},"intensity":{}}}"#,
                vec3(l.position),
                vec3(l.color.map(|c| c * l.intensity))
            ));
            continue;
        }
        let LightKind::Rect { width, height } = l.kind else {
            panic!("light {}: only rect and point lights are mapped onto Mitsuba here", l.name)
        };
        rects.push(format!(
            r#"{{"position":{},"direction":{},"right":{},"width":{},"height":{},"radiance":{}}}"#,
            vec3(l.position),
            vec3(l.direction),
            vec3(l.right),
            num(width),
            num(height),
            vec3(l.color.map(|c| c * l.intensity)),
        ));
    }
    // Mitsuba's medium fills all space (render.py): the same as kiln's box only if the box
    // holds the closed room the camera is in, which the medium test sets up.
    assert!(s.media.len() <= 1, "one medium at most maps onto Mitsuba here");
    let medium = s.media.first().map_or(String::new(), |m| {
        format!(
            r#","medium":{{"sigma_a":{},"sigma_s":{},"g":{}}}"#,
            vec3(m.sigma_a),
            vec3(m.sigma_s),
            num(m.g)
        )
    });
    // The environment goes as an .npy beside the scene (`env_npy`), rotation already applied.
    let environment = env_npy.map_or(String::new(), |p| format!(r#","environment":"{}""#, p.display()));
    format!(
        r#"{{"camera":{{"position":{},"target":{},"up":{},"vfov_degrees":{}}},"meshes":[{}],"rect_lights":[{}],"point_lights":[{}]{medium}{environment}}}"#,
        vec3(cam.position),
        vec3(cam.target),
        vec3(cam.up),
        num(cam.vfov_degrees),
        meshes.join(","),
        rects.join(","),
        points.join(","),
    )
}

/// Runs `render.py` with `args`; returns its last line of output, parsed.
fn python(python: &Path, args: &[&str]) -> serde_json::Value {
    let script = workspace().join("tests/mitsuba/render.py");
    let out = Command::new(python).arg(&script).args(args).output().expect("running Python");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "render.py {}: {}\n{stdout}{}",
        args.join(" "),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(stdout.trim().lines().last().unwrap_or("")).expect("a JSON line from render.py")
}

/// Red left, green right: the red wall must be on the left in both images (none is mirrored).
fn assert_red_left(name: &str, rgb: &[f32]) {
    let side = |x0: u32, x1: u32| {
        let mut s = [0.0f64; 3];
        for y in 0..H {
            for x in x0..x1 {
                let i = ((y * W + x) * 3) as usize;
                for c in 0..3 {
                    s[c] += rgb[i + c] as f64;
                }
            }
        }
        s
    };
    let (left, right) = (side(0, W / 4), side(W - W / 4, W));
    assert!(
        left[0] > left[1] && right[1] > right[0],
        "{name}: red wall not on the left ({left:?}, {right:?})"
    );
}

/// Renders `scene` with both (kiln at `kiln_spp`), compares, and asserts the bound on mean FLIP.
fn check(case: &str, scene: Scene, kiln_spp: u32) {
    let tmp = gpu_test!();
    let py = require!(mitsuba_python());
    let dir = match std::env::var_os("KILN_MITSUBA_OUT") {
        Some(d) => {
            let d = PathBuf::from(d);
            std::fs::create_dir_all(&d).unwrap();
            d
        }
        None => tmp.path().to_path_buf(),
    };
    let at = |name: &str| dir.join(format!("{case}-{name}"));
    let env_npy = scene.environment.as_ref().map(|e| {
        assert_eq!(e.rotation_degrees, 0.0, "the Mitsuba scene's environment is not rotated");
        let path = at("environment.npy");
        write_npy(&path, e.width, e.height, &e.pixels.concat());
        path
    });
    let cornell = scene.environment.is_none();
    std::fs::write(at("scene.json"), scene_json(&scene, env_npy.as_deref(), &at)).unwrap();
    let file = at("scene.kiln");
    std::fs::write(
        &file,
        compile(
            scene,
            // Textures as they are (no block compression), so that both renderers read the same.
            Settings {
                shaft_variants: Some(0),
                shadow_res: 64,
                media_volume_res: 4,
                texture_format: TextureFormat::Rgba8,
                ..Default::default()
            },
        ),
    )
    .unwrap();

    let options = Options::new(file, W, H).unshadowed().reference().build();
    let lock = MACHINE.lock().unwrap_or_else(|e| e.into_inner());
    let (report, rgb) = kiln_player::reference::render(&options, kiln_spp, Instant::now())
        .unwrap_or_else(|e| panic!("{case}: kiln reference render: {e}"));
    assert_eq!(rgb.len(), (W * H * 3) as usize);
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0), "{case}: kiln's image holds NaN, Inf or < 0");
    write_npy(&at("kiln.npy"), W, H, &rgb);
    let size = format!("{W}x{H}");
    let spp = MITSUBA_SPP.to_string();
    let (scene_path, mitsuba_path) = (at("scene.json"), at("mitsuba.npy"));
    let m =
        python(&py, &["render", &scene_path.to_string_lossy(), &mitsuba_path.to_string_lossy(), &spp, &size]);
    // The noise floor: Mitsuba at kiln's sample count, another seed.
    let control = at("mitsuba-control.npy");
    let spp_text = kiln_spp.to_string();
    python(
        &py,
        &["render", &scene_path.to_string_lossy(), &control.to_string_lossy(), &spp_text, &size, "1"],
    );
    drop(lock);
    let c = python(&py, &["compare", &mitsuba_path.to_string_lossy(), &at("kiln.npy").to_string_lossy()]);
    let n = python(&py, &["compare", &mitsuba_path.to_string_lossy(), &control.to_string_lossy()]);
    let (flip, rel_mse) = (c["mean_flip"].as_f64().unwrap(), c["rel_mse"].as_f64().unwrap());
    let mut ratio = String::new();
    let ratios: Vec<f64> = c["mean_ratio"].as_array().unwrap().iter().map(|r| r.as_f64().unwrap()).collect();
    for r in &ratios {
        let _ = write!(ratio, " {r:.4}");
    }
    eprintln!(
        "mitsuba check {case}: mean FLIP {flip:.4}, relMSE {rel_mse:.5}, kiln/mitsuba mean radiance (RGB){ratio}; \
         {W}x{H}, kiln {kiln_spp} spp in {:.1} s, mitsuba {MITSUBA_SPP} spp in {:.1} s; \
         noise floor (mitsuba {kiln_spp} spp, another seed): mean FLIP {:.4}, relMSE {:.5}",
        report.seconds,
        m["seconds"].as_f64().unwrap(),
        n["mean_flip"].as_f64().unwrap(),
        n["rel_mse"].as_f64().unwrap(),
    );
    if cornell {
        assert_red_left(&format!("{case} (kiln)"), &rgb);
        let mitsuba = read_npy(&mitsuba_path, W, H);
        assert_red_left(&format!("{case} (mitsuba)"), &mitsuba);
    }
    // Where Mitsuba's own noise at kiln's sample count exceeds the bound (glossy highlights), kiln
    // must come within NOISE_MARGIN of that noise instead: a bias adds to it (a coloured F0 read
    // as grey: 1.45 times the noise in the glossy case).
    let floor = n["mean_flip"].as_f64().unwrap();
    let bound = MAX_MEAN_FLIP.max(NOISE_MARGIN * floor);
    assert!(
        flip <= bound,
        "{case}: mean FLIP {flip:.4} > {bound:.4} (relMSE {rel_mse:.5}; Mitsuba's noise floor {floor:.4})"
    );
    assert!(
        ratios.len() == 3 && ratios.iter().all(|r| (r - 1.0).abs() <= MAX_MEAN_RATIO_ERROR),
        "{case}: kiln's mean radiance against Mitsuba's is{ratio} (RGB), beyond {MAX_MEAN_RATIO_ERROR}"
    );
}

#[test]
fn blocks_under_an_environment_map_match_mitsuba() {
    // A grey floor, a white block and a red one under an environment lit by a bright, small sun
    // patch (next-event estimation through the sampling table, MIS against BRDF sampling) over a
    // blue-to-orange sky and a dark ground; the camera sees the map behind the blocks, so a
    // flipped or shifted mapping shows in the background as well as in the light.
    let mut scene = Scene { name: "environment".into(), ..Default::default() };
    scene.materials.push(Material { name: "grey".into(), gpu: lambert_material([0.5; 3]) });
    scene.materials.push(Material { name: "white".into(), gpu: lambert_material([0.8; 3]) });
    scene.materials.push(Material { name: "red".into(), gpu: lambert_material([0.7, 0.1, 0.1]) });
    kiln_tests::boxes::quad(
        &mut scene,
        [Vec3::new(-3., 0., -3.), Vec3::new(-3., 0., 3.), Vec3::new(3., 0., 3.), Vec3::new(3., 0., -3.)],
        0,
    );
    kiln_tests::boxes::cuboid(&mut scene, Vec3::new(-1.2, 0., -0.8), Vec3::new(-0.2, 1.2, 0.2), 1, false);
    kiln_tests::boxes::cuboid(&mut scene, Vec3::new(0.4, 0., -0.2), Vec3::new(1.2, 0.6, 0.6), 2, false);
    scene.cameras.push(kiln_format::manifest::Camera {
        name: "c".into(),
        position: [0.5, 2.2, 4.5],
        target: [0.0, 0.6, 0.0],
        up: [0.0, 1.0, 0.0],
        vfov_degrees: 50.0,
        znear: 0.01,
        zfar: 0.0,
    });
    let (w, h) = (128u32, 64u32);
    let sun = Vec3::new(0.5, 0.6, 0.62).normalize();
    let pixels = (0..w * h)
        .map(|i| {
            let (u, v) = (((i % w) as f32 + 0.5) / w as f32, ((i / w) as f32 + 0.5) / h as f32);
            let (phi, theta) = (std::f32::consts::TAU * u, std::f32::consts::PI * v);
            let d = Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos());
            if d.dot(sun) > 0.995 {
                [60.0, 55.0, 45.0]
            } else if d.y > 0.0 {
                [
                    0.3 + 0.5 * (1.0 - d.y) + 0.2 * d.x.max(0.0),
                    0.4 + 0.2 * (1.0 - d.y),
                    0.9 - 0.3 * (1.0 - d.y),
                ]
            } else {
                [0.08, 0.07, 0.06]
            }
        })
        .collect::<Vec<_>>();
    scene.sky.radiance = [0.0; 3];
    scene.environment = Some(kiln_compiler::ir::EnvironmentImage {
        name: "test".into(),
        width: w,
        height: h,
        pixels,
        rotation_degrees: 0.0,
    });
    check("environment", scene, KILN_SPP);
}

#[test]
fn cornell_box_with_a_rect_light_matches_mitsuba() {
    let scene = cornell_box();
    assert!(matches!(scene.lights[..], [ref l] if matches!(l.kind, LightKind::Rect { .. })));
    check("rect", scene, KILN_SPP);
}

#[test]
fn cornell_box_with_vertex_colours_matches_mitsuba() {
    // Every vertex coloured by an affine function of its position (so that both renderers'
    // barycentric interpolation reproduce it exactly): green rises with height, blue with x. The
    // red wall stays red; the light's emission is not coloured. Mitsuba reads the colours as its
    // PLY `vertex_color` attribute times the albedo.
    let mut scene = cornell_box();
    let colors = scene
        .vertices
        .iter()
        .map(|v| {
            let p = v.position;
            [1.0, 0.55 + 0.2 * p[1], 0.6 + 0.3 * p[0], 1.0]
                .map(|c: f32| (c.clamp(0.0, 1.0) * 65535.0).round() as u16)
        })
        .collect();
    scene.set_colors(0, Some(colors));
    check("colors", scene, KILN_SPP);
}

#[test]
fn a_closed_room_full_of_fog_matches_mitsuba() {
    // The Cornell box closed by a white front wall, the camera inside it, the room filled with a
    // chromatic, forward-scattering homogeneous medium (optical depth 0.7-1.2 across the room):
    // single and multiple scattering, the rect light seen through the fog, shadow rays through
    // it, surfaces inside it.
    let mut scene = cornell_box();
    let corners =
        [Vec3::new(1., 0., 1.), Vec3::new(-1., 0., 1.), Vec3::new(-1., 2., 1.), Vec3::new(1., 2., 1.)];
    let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize();
    assert!(n.z < -0.999, "the front wall must face into the room");
    let base = scene.vertices.len() as u32;
    for c in corners {
        scene.vertices.push(Vertex { position: c.to_array(), normal: n.to_array() });
        if !scene.uvs.is_empty() {
            scene.uvs.push([0.0; 2]);
        }
    }
    scene.triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    scene.triangle_materials.extend([0; 2]); // white
    let cam = &mut scene.cameras[0];
    cam.position = [0.0, 1.0, 0.9];
    cam.target = [0.0, 0.9, 0.0];
    cam.vfov_degrees = 75.0;
    scene.media.push(Medium {
        bounds: Bounds { min: [-1.0, 0.0, -1.0], max: [1.0, 2.0, 1.0] },
        sigma_a: [0.05, 0.05, 0.1],
        sigma_s: [0.3, 0.4, 0.5],
        g: 0.4,
    });
    check("fog", scene, KILN_SPP_FOG);
}

#[test]
fn cornell_box_with_an_emissive_quad_matches_mitsuba() {
    let mut scene = cornell_box();
    // The rect light becomes two one-sided emissive triangles of the same size, place and
    // radiance, their front faces (counter-clockwise) down, a black Lambertian surface.
    let l = scene.lights.pop().unwrap();
    let LightKind::Rect { width, height } = l.kind else { panic!("the demo's light is a rect light") };
    let (p, d, r) = (Vec3::from(l.position), Vec3::from(l.direction), Vec3::from(l.right));
    let (r, u) = (r * 0.5 * width, d.cross(r) * 0.5 * height);
    let mut gpu = lambert_material([0.0; 3]);
    gpu.emission = l.color.map(|c| c * l.intensity);
    scene.materials.push(Material { name: "emitter".into(), gpu });
    let material = scene.materials.len() as u32 - 1;
    // Counter-clockwise seen from below (from `d`'s side): the normal (c1 − c0) × (c2 − c0) is d.
    let corners = [p - r - u, p + r - u, p + r + u, p - r + u];
    let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize();
    assert!(n.dot(d) > 0.999, "the emissive quad must face the way the light did");
    let base = scene.vertices.len() as u32;
    for c in corners {
        scene.vertices.push(Vertex { position: c.to_array(), normal: n.to_array() });
        if !scene.uvs.is_empty() {
            scene.uvs.push([0.0; 2]);
        }
    }
    scene.triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    scene.triangle_materials.extend([material; 2]);
    check("emissive", scene, KILN_SPP);
}

#[test]
fn glossy_blocks_in_the_cornell_box_match_mitsuba() {
    // glTF's metallic-roughness BSDF (Mitsuba through `tests/mitsuba/gltf_bsdf.py`): the demo box
    // with its blocks made a rough gold metal and a green glass with a coloured F0
    // (KHR_materials_specular) that transmits 70 % of its diffuse light (KHR_materials_transmission,
    // thin-walled: the light reaches the floor through its walls, the back wall is seen through
    // them), and the floor a rough blue dielectric under a smooth clear coat
    // (KHR_materials_clearcoat: car paint) that mirrors the room and the light. The rect light's
    // highlights on them come from next-event estimation, the reflections of the walls from
    // sampling the GGX lobes, both weighted by MIS.
    let mut scene = cornell_box();
    let mut add = |name: &str, gpu: GpuMaterial| {
        scene.materials.push(Material { name: name.into(), gpu });
        scene.materials.len() as u32 - 1
    };
    let gold = add(
        "gold",
        GpuMaterial {
            base_color: [1.0, 0.78, 0.34, 1.0],
            metallic: 1.0,
            roughness: 0.35,
            ..GpuMaterial::default()
        },
    );
    let mut tinted = GpuMaterial {
        base_color: [0.2, 0.5, 0.25, 1.0],
        metallic: 0.0,
        roughness: 0.25,
        transmission: 0.7,
        ..GpuMaterial::default()
    };
    tinted.set_dielectric([0.25, 0.12, 0.4], 0.8);
    let tinted = add("tinted", tinted);
    let floor = add(
        "floor",
        GpuMaterial {
            base_color: [0.3, 0.35, 0.6, 1.0],
            metallic: 0.0,
            roughness: 0.6,
            clearcoat: 1.0,
            clearcoat_roughness: 0.15,
            ..GpuMaterial::default()
        },
    );
    // The demo's triangles: the floor's two first, then the other walls' (8), then the two
    // blocks' (short, tall), five faces of two triangles each.
    let blocks = 10;
    let n = scene.triangle_materials.len();
    assert_eq!(n, 10 + 2 * blocks, "the demo box's five walls and two blocks");
    for (i, m) in scene.triangle_materials.iter_mut().enumerate() {
        if i < 2 {
            *m = floor;
        } else if i >= n - 2 * blocks && i < n - blocks {
            *m = tinted;
        } else if i >= n - blocks {
            *m = gold;
        }
    }
    check("glossy", scene, KILN_SPP);
}

/// A public model from `../shared/scenes/khronos` under the built-in studio environment, seen by
/// `camera` (or the file's first camera). None, with a message, when the shared scenes are absent.
fn khronos_under_the_studio(path: &str, camera: Option<kiln_format::manifest::Camera>) -> Option<Scene> {
    let scenes = kiln_tests::shared_scenes()?;
    let mut scene =
        kiln_compiler::import::import(&scenes.join("khronos").join(path)).expect("the model imports");
    use kiln_compiler::import::environment::{EnvironmentSpec, Placement, apply};
    apply(&mut scene, &EnvironmentSpec::Studio, Placement::default(), "test").unwrap();
    scene.sky.radiance = [0.0; 3];
    if let Some(c) = camera {
        scene.cameras.insert(0, c);
    }
    Some(scene)
}

// The Khronos models are not part of the repository (`../shared/scenes` beside the checkout)
// and take minutes on lavapipe: run with `cargo test --release -p kiln-tests --test mitsuba --
// --ignored`.

#[test]
#[ignore = "a public model from ../shared/scenes; minutes on lavapipe"]
fn damaged_helmet_under_the_studio_matches_mitsuba() {
    // Every texture of the glTF BSDF at once: base colour, metallic-roughness, a normal map and
    // an emissive texture, lit by an environment map (issue 44's target: FLIP 0.05).
    let camera = kiln_format::manifest::Camera {
        name: "front".into(),
        position: [0.6, 0.3, 2.6],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        vfov_degrees: 45.0,
        znear: 0.01,
        zfar: 0.0,
    };
    let Some(scene) = khronos_under_the_studio("DamagedHelmet/glTF-Binary/DamagedHelmet.glb", Some(camera))
    else {
        return;
    };
    check("helmet", scene, KILN_SPP);
}

#[test]
#[ignore = "a public model from ../shared/scenes; minutes on lavapipe"]
fn toy_car_under_the_studio_matches_mitsuba() {
    // KHR_materials_clearcoat with its texture over a textured, normal-mapped body (issue 45's
    // target: FLIP 0.06), the windows a thin-walled transmission, 7 cm across, from the file's
    // first camera.
    let Some(scene) = khronos_under_the_studio("ToyCar/glTF/ToyCar.gltf", None) else {
        return;
    };
    assert!(scene.materials.iter().any(|m| m.gpu.clearcoat > 0.0 && m.gpu.clearcoat_texture != NO_TEXTURE));
    check("toycar", scene, KILN_SPP);
}

#[test]
#[ignore = "a public model from ../shared/scenes; minutes on lavapipe"]
fn lamp_under_the_studio_matches_mitsuba() {
    // KHR_materials_transmission with its texture: the lamp's paper shade, lit from inside by
    // the file's point light and outside by the studio (issue 45's target: FLIP 0.06).
    let camera = kiln_format::manifest::Camera {
        name: "shade".into(),
        position: [0.5, 1.4, 2.0],
        target: [0.15, 1.1, 0.0],
        up: [0.0, 1.0, 0.0],
        vfov_degrees: 35.0,
        znear: 0.01,
        zfar: 0.0,
    };
    let Some(scene) =
        khronos_under_the_studio("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf", Some(camera))
    else {
        return;
    };
    assert!(
        scene.materials.iter().any(|m| m.gpu.transmission > 0.0 && m.gpu.transmission_texture != NO_TEXTURE)
    );
    check("lamp", scene, KILN_SPP);
}
