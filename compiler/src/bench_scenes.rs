//! Seeded benchmark scenes after seed 004's Table 1: a Cornell box (32 triangles: the thesis's
//! has 36, our blocks have no bottoms; or 12 around an object) and bumpy spherical objects with
//! exactly the thesis meshes' triangle counts (Utah teapot 15,704, Stanford bunny 69,451, Stanford
//! dragon 871,306: the meshes themselves are not available here).

use glam::Vec3;
use kiln_format::manifest::{Light, LightKind};
use kiln_format::sections::Vertex;

use crate::bake::linespace::SceneAttributes;
use crate::import::demo;
use crate::ir::{Material, Scene};

/// The thesis's object triangle counts.
pub const TEAPOT: usize = 15_704;
/// Stanford bunny.
pub const BUNNY: usize = 69_451;
/// Stanford dragon.
pub const DRAGON: usize = 871_306;

/// The box's triangles in a scene with an object (walls and light quad), numbered before the
/// object's.
pub const BOX_TRIANGLES: u32 = 12;

/// One configuration of seed 004's Table 1 and the thesis's times for it (GTX 1080).
#[derive(Debug, Clone, Copy)]
pub struct Table1Row {
    /// The thesis's scene number.
    pub scene: u32,
    /// Triangles of the object in the box (0: scene 4's box with its blocks).
    pub object: usize,
    /// Voxel cells along the longest axis.
    pub res: u32,
    /// Shaft resolution N.
    pub n: u32,
    /// The thesis's voxelization time, ms.
    pub thesis_voxel_ms: f64,
    /// The thesis's (PNMT) line-space generation time, ms.
    pub thesis_ls_ms: f64,
}

/// Seed 004's Table 1, row by row.
pub const TABLE1: [Table1Row; 8] = [
    Table1Row { scene: 4, object: 0, res: 8, n: 4, thesis_voxel_ms: 43.0, thesis_ls_ms: 154.0 },
    Table1Row { scene: 4, object: 0, res: 8, n: 5, thesis_voxel_ms: 43.0, thesis_ls_ms: 269.0 },
    Table1Row { scene: 5, object: TEAPOT, res: 8, n: 5, thesis_voxel_ms: 58.0, thesis_ls_ms: 644.0 },
    Table1Row { scene: 5, object: TEAPOT, res: 32, n: 5, thesis_voxel_ms: 47.0, thesis_ls_ms: 1795.0 },
    Table1Row { scene: 6, object: BUNNY, res: 8, n: 5, thesis_voxel_ms: 51.0, thesis_ls_ms: 3915.0 },
    Table1Row { scene: 6, object: BUNNY, res: 64, n: 5, thesis_voxel_ms: 71.0, thesis_ls_ms: 10081.0 },
    Table1Row { scene: 7, object: DRAGON, res: 8, n: 5, thesis_voxel_ms: 95.0, thesis_ls_ms: 94393.0 },
    Table1Row { scene: 7, object: DRAGON, res: 72, n: 5, thesis_voxel_ms: 88.0, thesis_ls_ms: 53675.0 },
];

/// A benchmark scene's triangle attributes for the line space, in the scene's own order.
pub fn attributes(scene: &Scene) -> SceneAttributes<'_> {
    SceneAttributes {
        vertices: &scene.vertices,
        uvs: &scene.uvs,
        triangles: &scene.triangles,
        materials: &scene.triangle_materials,
    }
}

/// The Cornell box of scene 4 (walls, two blocks, a light quad: 32 triangles), or with
/// `object_triangles > 0` the 12-triangle box (walls and light quad) around a seeded object of
/// exactly that many triangles.
pub fn cornell_with_object(object_triangles: usize, seed: u64) -> Scene {
    let mut s = demo::cornell_box();
    s.name = format!("box+{object_triangles}");
    if object_triangles > 0 {
        // Keep the 5 walls (10 triangles), drop the blocks.
        s.triangles.truncate(10);
        s.triangle_materials.truncate(10);
    }
    // The light quad just below the ceiling (2 triangles).
    let base = s.vertices.len() as u32;
    for p in [[-0.25, 1.98, -0.2], [0.25, 1.98, -0.2], [0.25, 1.98, 0.2], [-0.25, 1.98, 0.2]] {
        s.vertices.push(Vertex { position: p, normal: [0.0, -1.0, 0.0] });
        s.uvs.push([0.0; 2]);
    }
    s.triangles.extend([[base, base + 2, base + 1], [base, base + 3, base + 2]]);
    s.triangle_materials.extend([0, 0]);
    if object_triangles > 0 {
        s.materials.push(Material {
            name: "object".into(),
            gpu: crate::import::demo::lambert_material([0.8, 0.8, 0.8]),
        });
        let material = (s.materials.len() - 1) as u32;
        spiral_blob(&mut s, object_triangles, Vec3::new(0.0, 0.7, 0.0), 0.6, seed, material);
    }
    s.lights = vec![Light {
        name: "ceiling".into(),
        kind: LightKind::Rect { width: 0.5, height: 0.4 },
        position: [0.0, 1.97, 0.0],
        direction: [0.0, -1.0, 0.0],
        right: [1.0, 0.0, 0.0],
        color: [1.0; 3],
        intensity: 10.0,
        range: 0.0,
        casts_shadows: true,
    }];
    s
}

/// Adds a closed-looking bumpy sphere made of one triangle strip spiralling from pole to pole:
/// exactly `n` triangles of similar size.
fn spiral_blob(s: &mut Scene, n: usize, centre: Vec3, radius: f32, seed: u64, material: u32) {
    let quads = n / 2;
    let turns = ((quads as f64).sqrt() / 2.0).max(1.0);
    let mut rng = crate::raycheck::Rng::new(seed);
    let bumps: Vec<(Vec3, f32)> = (0..24).map(|_| (rng.direction(), 0.05 + 0.1 * rng.f32())).collect();
    let point = |s_: f64, edge: f64| {
        let band = std::f64::consts::PI / (turns + 1.0);
        let theta = (std::f64::consts::PI - band) * s_ + band * edge;
        let phi = std::f64::consts::TAU * turns * s_;
        let d =
            Vec3::new((theta.sin() * phi.cos()) as f32, theta.cos() as f32, (theta.sin() * phi.sin()) as f32);
        let bump: f32 = bumps.iter().map(|(c, a)| a * (-(1.0 - d.dot(*c)) * 12.0).exp()).sum();
        centre + d * radius * (1.0 + bump)
    };
    let base = s.vertices.len() as u32;
    let columns = quads + 1;
    for i in 0..columns {
        let t = i as f64 / quads.max(1) as f64;
        for edge in [0.0, 1.0] {
            let p = point(t, edge);
            s.vertices.push(Vertex { position: p.to_array(), normal: ((p - centre).normalize()).to_array() });
            s.uvs.push([0.0; 2]);
        }
    }
    for i in 0..quads as u32 {
        let (a, b, c, d) = (base + 2 * i, base + 2 * i + 1, base + 2 * i + 2, base + 2 * i + 3);
        s.triangles.extend([[a, c, b], [b, c, d]]);
    }
    if n % 2 == 1 {
        let last = base + 2 * quads as u32;
        s.triangles.push([last, last + 1, base]);
    }
    s.triangle_materials.extend(std::iter::repeat_n(material, n));
}
