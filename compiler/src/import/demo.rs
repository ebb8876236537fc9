//! The built-in demo scene: a Cornell box (2 × 2 × 2 units, floor at y = 0) with a short and a
//! tall block, Lambertian materials with the classic albedos, a rectangular ceiling light and a
//! camera looking in through the open side.

use glam::{Mat3, Vec3};
use kiln_format::manifest::{Camera, Light, LightKind, Sky};
use kiln_format::sections::Vertex;

use super::obj::lambert;

/// A pure Lambertian material of albedo `kd` (as the OBJ rule makes for `Ks 0 0 0`).
pub fn lambert_material(kd: [f32; 3]) -> kiln_format::sections::GpuMaterial {
    lambert(kd)
}
use crate::ir::{Material, Scene};

/// The sidecar equivalent of the demo's camera and light, for documentation and tests.
pub const DEMO_SIDECAR: &str = r#"[camera]
position = [0.0, 1.0, 3.3]
target = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov_degrees = 40.0

[[light]]
kind = "rect"
position = [0.0, 1.98, 0.0]
direction = [0.0, -1.0, 0.0]
right = [1.0, 0.0, 0.0]
size = [0.5, 0.4]
color = [1.0, 0.85, 0.6]
intensity = 20.0
"#;

/// Builds the demo scene.
pub fn cornell_box() -> Scene {
    let mut s = Scene { name: "demo".into(), ..Default::default() };
    for (name, kd) in
        [("white", [0.73, 0.73, 0.73]), ("red", [0.63, 0.065, 0.05]), ("green", [0.14, 0.45, 0.091])]
    {
        s.materials.push(Material { name: name.into(), gpu: lambert(kd) });
    }
    let (white, red, green) = (0, 1, 2);
    let v = Vec3::new;
    // Walls, each a quad with its front face towards the inside of the box.
    quad(&mut s, [v(-1., 0., 1.), v(1., 0., 1.), v(1., 0., -1.), v(-1., 0., -1.)], white); // floor
    quad(&mut s, [v(-1., 2., -1.), v(1., 2., -1.), v(1., 2., 1.), v(-1., 2., 1.)], white); // ceiling
    quad(&mut s, [v(-1., 0., -1.), v(1., 0., -1.), v(1., 2., -1.), v(-1., 2., -1.)], white); // back
    quad(&mut s, [v(-1., 0., 1.), v(-1., 0., -1.), v(-1., 2., -1.), v(-1., 2., 1.)], red); // left
    quad(&mut s, [v(1., 0., -1.), v(1., 0., 1.), v(1., 2., 1.), v(1., 2., -1.)], green); // right
    block(&mut s, v(0.35, 0.0, 0.3), v(0.3, 0.3, 0.3), -17.0, white);
    block(&mut s, v(-0.35, 0.0, -0.3), v(0.3, 0.6, 0.3), 16.0, white);
    s.lights.push(Light {
        name: "ceiling".into(),
        kind: LightKind::Rect { width: 0.5, height: 0.4 },
        position: [0.0, 1.98, 0.0],
        direction: [0.0, -1.0, 0.0],
        right: [1.0, 0.0, 0.0],
        color: [1.0, 0.85, 0.6],
        intensity: 20.0,
        range: 0.0,
        casts_shadows: true,
    });
    s.cameras.push(Camera {
        name: "front".into(),
        position: [0.0, 1.0, 3.3],
        target: [0.0, 1.0, 0.0],
        up: [0.0, 1.0, 0.0],
        vfov_degrees: 40.0,
        znear: 0.01,
        zfar: 0.0,
    });
    s.sky = Sky { radiance: [0.0; 3] };
    s
}

/// Adds a planar quad (corners counter-clockwise seen from its front) as two triangles.
fn quad(s: &mut Scene, c: [Vec3; 4], material: u32) {
    let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize();
    let base = s.vertices.len() as u32;
    for p in c {
        s.vertices.push(Vertex { position: p.to_array(), normal: n.to_array() });
        s.uvs.push([0.0; 2]);
    }
    s.triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    s.triangle_materials.extend([material; 2]);
}

/// Adds a box standing on y = `base.y`, centred at `base.xz`, half extents `half` (y: full
/// height / 2), turned by `degrees` about the vertical axis.
fn block(s: &mut Scene, base: Vec3, half: Vec3, degrees: f32, material: u32) {
    let r = Mat3::from_rotation_y(degrees.to_radians());
    let p = |x: f32, y: f32, z: f32| base + r * Vec3::new(x * half.x, (y + 1.0) * half.y, z * half.z);
    let faces = [
        [p(-1., 1., 1.), p(1., 1., 1.), p(1., 1., -1.), p(-1., 1., -1.)], // top
        [p(-1., -1., 1.), p(1., -1., 1.), p(1., 1., 1.), p(-1., 1., 1.)], // front (+z)
        [p(1., -1., -1.), p(-1., -1., -1.), p(-1., 1., -1.), p(1., 1., -1.)], // back
        [p(1., -1., 1.), p(1., -1., -1.), p(1., 1., -1.), p(1., 1., 1.)], // +x
        [p(-1., -1., -1.), p(-1., -1., 1.), p(-1., 1., 1.), p(-1., 1., -1.)], // -x
    ];
    for f in faces {
        quad(s, f, material);
    }
}
