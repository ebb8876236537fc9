//! One light on a diffuse plane, every pixel against its closed form: albedo/π · I cos/d² for a
//! point light, albedo/π · E cos for a directional one.

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_compiler::ir::TextureRole;
use kiln_compiler::settings::{Settings, TextureFormat};
use kiln_format::manifest::{LightKind, Sky};
use kiln_format::sections::MaterialFlags;
use kiln_test_support::gpu_test;
use kiln_tests::{GBuffer, Options, compile, scene_of};

use crate::harness::{
    ALBEDO, H, Pinhole, TOLERANCE, W, albedo, compare_plane, fast_settings, light, render, square,
    square_uvs, srgb8, texture,
};

#[test]
fn point_light_on_a_diffuse_plane_matches_albedo_over_pi_times_i_cos_over_d2() {
    let dir = gpu_test!();
    let cam = Pinhole::new([0.0, 8.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 60.0, W, H);
    let mut scene = scene_of(&square(0.0, 10.0));
    scene.materials[0].gpu = lambert_material(ALBEDO.map(srgb8));
    let lp = [1.0f32, 3.0, -0.5];
    let intensity = 10.0;
    scene.lights.push(light(LightKind::Point, lp, [0.0, -1.0, 0.0], intensity));
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let a = albedo();
    let l = DVec3::from_array(lp.map(f64::from));
    // Both G-buffers: rasterised, and the visibility buffer resolved in compute.
    for mode in [GBuffer::Raster, GBuffer::Visibility] {
        let (rgb, _) =
            render(dir.path(), &format!("point-{mode:?}"), &bytes, |f| Options::new(f, W, H).gbuffer(mode));
        let n = compare_plane(
            &rgb,
            &cam,
            9.5,
            |_, _| true,
            |p| {
                let to = l - p;
                let d2 = to.length_squared();
                let cos = to.y / d2.sqrt();
                a.map(|k| k / std::f64::consts::PI * intensity as f64 * cos / d2)
            },
            TOLERANCE,
        );
        assert!(n > (W * H / 2) as usize, "{mode:?}: only {n} pixels compared");
    }
}

#[test]
fn directional_light_on_a_diffuse_plane_is_albedo_over_pi_times_e_cos() {
    let dir = gpu_test!();
    let cam = Pinhole::new([3.0, 6.0, 5.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 50.0, W, H);
    let mut scene = scene_of(&square(0.0, 10.0));
    scene.materials[0].gpu = lambert_material(ALBEDO.map(srgb8));
    let travel = Vec3::new(-0.3, -1.0, 0.2).normalize();
    let irradiance = 3.0;
    scene.lights.push(light(LightKind::Directional, [0.0; 3], travel.to_array(), irradiance));
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let (rgb, _) = render(dir.path(), "directional", &bytes, |f| Options::new(f, W, H));
    let a = albedo();
    let cos = -travel.y as f64;
    let n = compare_plane(
        &rgb,
        &cam,
        9.5,
        |_, _| true,
        |_| a.map(|k| k / std::f64::consts::PI * irradiance as f64 * cos),
        TOLERANCE,
    );
    assert!(n > (W * H / 3) as usize, "only {n} pixels compared");
}

#[test]
fn an_orthographic_camera_sees_the_lit_square_where_its_parallel_rays_meet_it() {
    let dir = gpu_test!();
    // Straight down onto a 6 × 6 square lit by a directional light, through an orthographic
    // camera 4 units high (half extents): pixel (px, py) looks at x = ndc.x · 4 · aspect,
    // z = −ndc.y · 4 (right = +x, up = −z). Inside the square: albedo/π · E cos; outside: the
    // black sky. Both G-buffers and the reference path tracer. The square's vertex colours fall
    // linearly along x, so that a surface point found off the pixel's parallel ray (the
    // visibility resolve's barycentrics) shows the wrong shade.
    let shade = |x: f64| 0.6 + 0.3 * x / 3.0;
    let ymag = 4.0f64;
    let aspect = W as f64 / H as f64;
    let mut scene = scene_of(&square(0.0, 3.0));
    scene.materials[0].gpu = lambert_material(ALBEDO.map(srgb8));
    let colors = scene
        .vertices
        .iter()
        .map(|v| [shade(v.position[0] as f64); 3].map(|c| (c * 65535.0).round() as u16))
        .map(|[r, g, b]| [r, g, b, u16::MAX])
        .collect();
    scene.set_colors(0, Some(colors));
    let travel = Vec3::new(-0.3, -1.0, 0.2).normalize();
    let irradiance = 3.0;
    scene.lights.push(light(LightKind::Directional, [0.0; 3], travel.to_array(), irradiance));
    scene.sky = Sky { radiance: [0.0; 3] };
    let cam = Pinhole::new([0.0, 8.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 60.0, W, H);
    scene.cameras.push(cam.file_camera());
    scene.orthographic.push(kiln_format::manifest::OrthographicCamera {
        camera: 0,
        xmag: (ymag * aspect) as f32,
        ymag: ymag as f32,
    });
    let bytes = compile(scene, fast_settings());
    let lit = albedo().map(|k| k / std::f64::consts::PI * irradiance as f64 * -travel.y as f64);
    let check = |rgb: &[f32], what: &str| {
        let (mut inside, mut outside) = (0, 0);
        for py in 0..H {
            for px in 0..W {
                let ndc =
                    ((px as f64 + 0.5) / W as f64 * 2.0 - 1.0, 1.0 - (py as f64 + 0.5) / H as f64 * 2.0);
                let (x, z) = (ndc.0 * ymag * aspect, -ndc.1 * ymag);
                let i = ((py * W + px) * 3) as usize;
                // A pixel is 8/72 units wide: stay a pixel away from the square's edges.
                if x.abs() < 2.85 && z.abs() < 2.85 {
                    for c in 0..3 {
                        let want = lit[c] * shade(x);
                        let rel = (rgb[i + c] as f64 - want).abs() / want;
                        // The albedo target is 8-bit sRGB and the shaded albedo no sRGB code.
                        assert!(
                            rel < TOLERANCE + 0.006,
                            "{what}: pixel ({px}, {py}) channel {c}: {} vs {want}",
                            rgb[i + c]
                        );
                    }
                    inside += 1;
                } else if x.abs() > 3.15 || z.abs() > 3.15 {
                    assert!(
                        rgb[i..i + 3].iter().all(|&v| v == 0.0),
                        "{what}: pixel ({px}, {py}) off the square is {:?}",
                        &rgb[i..i + 3]
                    );
                    outside += 1;
                }
            }
        }
        assert!(inside > 1000 && outside > 1000, "{what}: {inside} inside, {outside} outside");
    };
    for mode in [GBuffer::Raster, GBuffer::Visibility] {
        let (rgb, _) =
            render(dir.path(), &format!("ortho-{mode:?}"), &bytes, |f| Options::new(f, W, H).gbuffer(mode));
        check(&rgb, &format!("{mode:?}"));
    }
    let file = dir.path().join("ortho-ref.kiln");
    std::fs::write(&file, &bytes).unwrap();
    let o = Options::new(&file, W, H).build();
    let (_, rgb) =
        kiln_player::reference::render(&o, 4, std::time::Instant::now()).expect("reference render");
    check(&rgb, "reference");
}

/// A normal map tilting a floor's shading normal 60° towards −z (worked out here from the
/// texel's codes: tangent +x along u, glTF's green axis up the image, where v decreases), under a
/// directional light straight down and a black sky. Seen from −z, facing the tilt, every pixel is
/// Lambert's albedo/π · E · (n·ŷ); seen from +z, where the shading normal faces away from the eye
/// (n·v < 0) while the surface faces it, every pixel is black: the path tracer reflects nothing
/// towards a direction below the shading normal (as Mitsuba 3's BSDFs), and the frame's passes
/// agree. Both G-buffers and the reference path tracer. Planted and seen failing: the cotangent
/// frame's bitangent not negated (common/normalmap.glsl: the frame lit from +z and black from −z);
/// the direct pass keeping a normal that faces away from the eye (the floor lit from +z).
#[test]
fn a_normal_map_tilts_the_floor_the_same_way_in_the_frame_and_the_path_tracer() {
    let dir = gpu_test!();
    let mut scene = scene_of(&square(0.0, 10.0));
    square_uvs(&mut scene, 1.0);
    // Tangent-space (0, sin 60°, cos 60°) as 8-bit codes; z is rebuilt from x and y.
    let codes = [128u8, 238, 191, 255];
    scene.textures.push(texture("tilt", 4, 4, TextureRole::Normal, |_, _| codes));
    let m = &mut scene.materials[0].gpu;
    *m = lambert_material(ALBEDO.map(srgb8));
    m.normal_texture = 0;
    let irradiance = 2.0;
    scene.lights.push(light(LightKind::Directional, [0.0; 3], [0.0, -1.0, 0.0], irradiance));
    scene.sky = Sky { radiance: [0.0; 3] };
    let unit = |c: u8| c as f64 / 255.0 * 2.0 - 1.0;
    let (x, y) = (unit(codes[0]), unit(codes[1]));
    let n = DVec3::new(x, (1.0 - x * x - y * y).sqrt(), -y).normalize();
    let a = albedo();
    let lit = a.map(|k| k / std::f64::consts::PI * irradiance as f64 * n.y);
    for (side, z) in [("facing", -8.0), ("away", 8.0)] {
        let cam = Pinhole::new([0.0, 2.0, z], [0.0, 0.0, -z / 4.0], [0.0, 1.0, 0.0], 50.0, W, H);
        let mut scene = scene.clone();
        scene.cameras.push(cam.file_camera());
        let bytes = compile(scene, Settings { texture_format: TextureFormat::Rgba8, ..fast_settings() });
        let pixels = crate::harness::floor_pixels(&cam, 9.5);
        let away = side == "away";
        assert!(
            pixels.iter().all(|&(_, p, _)| (n.dot(cam.eye - p) < 0.0) == away),
            "{side}: the shading normal does not face the way the test means"
        );
        let check = |name: &str, rgb: &[f32]| {
            eprintln!("{side}, {name}:");
            if away {
                let bright = pixels.iter().map(|&(i, _, _)| rgb[i]).fold(0.0f32, f32::max);
                assert!(bright == 0.0, "{side}, {name}: a floor pixel is {bright}, not black");
            } else {
                let compared = compare_plane(rgb, &cam, 9.5, |_, _| true, |_| lit, TOLERANCE);
                assert!(compared > (W * H / 3) as usize, "{side}, {name}: only {compared} pixels compared");
            }
        };
        for mode in [GBuffer::Raster, GBuffer::Visibility] {
            let name = format!("tilt-{side}-{mode:?}");
            let (rgb, _) = render(dir.path(), &name, &bytes, |f| Options::new(f, W, H).gbuffer(mode));
            check(&format!("{mode:?}"), &rgb);
        }
        let file = dir.path().join(format!("tilt-{side}.kiln"));
        std::fs::write(&file, &bytes).unwrap();
        let o = Options::new(&file, W, H).unshadowed().reference().build();
        let (_, rgb) =
            kiln_player::reference::render(&o, 2, std::time::Instant::now()).expect("reference render");
        check("reference", &rgb);
    }
}

/// A thin-walled transmitting sheet (KHR_materials_transmission: t = 1, roughness 0.6, glTF's
/// core F0 0.04) at y = 0, lit only from below by a slanting directional light, the sky black:
/// everything the camera above sees comes through the transmitted lobe, E (1 − F) t c D Vis (n·l′)
/// per pixel, l′ the direction to the light mirrored through the sheet, h the half vector of v and
/// l′, D and Vis glTF's GGX and height-correlated Smith terms with α = roughness², F Schlick's at
/// v·h, all written here from the glTF specification. Both G-buffers with shadow maps, the
/// visibility G-buffer with ray-traced shadows, and the path tracer. Planted and seen failing: the
/// ray-traced shadows refusing lights below the surface (black), the lobe turned by negating the
/// light's direction instead of mirroring it.
#[test]
fn light_from_behind_comes_through_a_transmitting_sheet_by_the_mirrored_lobe() {
    let dir = gpu_test!();
    let cam = Pinhole::new([0.0, 6.0, 7.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 55.0, W, H);
    let mut scene = scene_of(&square(0.0, 10.0));
    let roughness = 0.6f32;
    let m = &mut scene.materials[0].gpu;
    *m = lambert_material(ALBEDO.map(srgb8));
    m.flags &= !MaterialFlags::DIFFUSE_ONLY;
    m.flags |= MaterialFlags::DOUBLE_SIDED;
    m.metallic = 0.0;
    m.roughness = roughness;
    m.transmission = 1.0;
    let irradiance = 3.0;
    let travel = DVec3::new(0.3, 1.0, -0.2).normalize();
    scene.lights.push(light(LightKind::Directional, [0.0; 3], travel.as_vec3().to_array(), irradiance));
    scene.sky = Sky { radiance: [0.0; 3] };
    scene.cameras.push(cam.file_camera());
    let bytes = compile(scene, fast_settings());
    let c = albedo();
    let a2 = (roughness as f64).powi(4);
    let expected = |p: DVec3| {
        let n = DVec3::Y;
        let v = (cam.eye - p).normalize();
        let l = DVec3::new(-travel.x, travel.y, -travel.z); // towards the light, mirrored
        let h = (v + l).normalize();
        let (n_h, n_v, n_l) = (n.dot(h), n.dot(v), n.dot(l));
        let d = a2 / (std::f64::consts::PI * (n_h * n_h * (a2 - 1.0) + 1.0).powi(2));
        let vis =
            0.5 / (n_l * (n_v * n_v * (1.0 - a2) + a2).sqrt() + n_v * (n_l * n_l * (1.0 - a2) + a2).sqrt());
        let f = 0.04 + 0.96 * (1.0 - v.dot(h)).powi(5);
        c.map(|k| irradiance as f64 * (1.0 - f) * k * d * vis * n_l)
    };
    let check = |name: &str, rgb: &[f32], tolerance: f64| {
        eprintln!("{name}:");
        let n = compare_plane(rgb, &cam, 9.5, |_, _| true, expected, tolerance);
        assert!(n > (W * H / 3) as usize, "{name}: only {n} pixels compared");
    };
    for mode in [GBuffer::Raster, GBuffer::Visibility] {
        let (rgb, _) =
            render(dir.path(), &format!("sheet-{mode:?}"), &bytes, |f| Options::new(f, W, H).gbuffer(mode));
        check(&format!("{mode:?}, shadow maps"), &rgb, TOLERANCE);
    }
    let (rgb, _) = render(dir.path(), "sheet-rt", &bytes, |f| {
        Options::new(f, W, H).gbuffer(GBuffer::Visibility).rt_shadows(0.0, 0.0)
    });
    check("visibility, ray-traced shadows", &rgb, TOLERANCE);
    let file = dir.path().join("sheet.kiln");
    std::fs::write(&file, &bytes).unwrap();
    let o = Options::new(&file, W, H).reference().build();
    let (_, rgb) =
        kiln_player::reference::render(&o, 4, std::time::Instant::now()).expect("reference render");
    // The path tracer's samples spread over each pixel, where the closed form is taken at its
    // centre.
    check("reference", &rgb, 0.02);
}
