//! One light on a diffuse plane, every pixel against its closed form: albedo/π · I cos/d² for a
//! point light, albedo/π · E cos for a directional one.

use glam::{DVec3, Vec3};
use kiln_compiler::import::demo::lambert_material;
use kiln_format::manifest::{LightKind, Sky};
use kiln_tests::{GBuffer, Options, compile, scene_of, vulkan};

use crate::harness::{
    ALBEDO, H, Pinhole, TOLERANCE, W, albedo, compare_plane, fast_settings, light, render, square, srgb8,
};

#[test]
fn point_light_on_a_diffuse_plane_matches_albedo_over_pi_times_i_cos_over_d2() {
    if !vulkan() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
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
    if !vulkan() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
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
