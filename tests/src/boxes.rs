//! Quads and boxes built into a scene in code: rooms, walls and slabs for the lighting tests.

use glam::Vec3;
use kiln_compiler::ir::Scene;
use kiln_format::sections::Vertex;

/// Adds quad `c` (counter-clockwise seen from its front, flat normals) of material `m`.
pub fn quad(s: &mut Scene, c: [Vec3; 4], m: u32) {
    let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize();
    let b = s.vertices.len() as u32;
    for p in c {
        s.vertices.push(Vertex { position: p.to_array(), normal: n.to_array() });
    }
    s.triangles.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
    s.triangle_materials.extend([m, m]);
}

/// Adds the six faces of the box `lo`..`hi` of material `m`, fronts facing in (`inward`: a
/// room) or out (a solid).
pub fn cuboid(s: &mut Scene, lo: Vec3, hi: Vec3, m: u32, inward: bool) {
    let p = |x: usize, y: usize, z: usize| Vec3::new([lo.x, hi.x][x], [lo.y, hi.y][y], [lo.z, hi.z][z]);
    // Each face counter-clockwise seen from outside.
    for mut f in [
        [p(0, 0, 0), p(0, 0, 1), p(0, 1, 1), p(0, 1, 0)],
        [p(1, 0, 0), p(1, 1, 0), p(1, 1, 1), p(1, 0, 1)],
        [p(0, 0, 0), p(1, 0, 0), p(1, 0, 1), p(0, 0, 1)],
        [p(0, 1, 0), p(0, 1, 1), p(1, 1, 1), p(1, 1, 0)],
        [p(0, 0, 0), p(0, 1, 0), p(1, 1, 0), p(1, 0, 0)],
        [p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1)],
    ] {
        if inward {
            f.reverse();
        }
        quad(s, f, m);
    }
}
