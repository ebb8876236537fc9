//! Shared helpers of the workspace-level tests: scenes built in code and compiled in memory.

use std::path::PathBuf;
use std::time::Instant;

use glam::Vec3;
use kiln_compiler::analyze::plan::Plan;
use kiln_compiler::bake;
use kiln_compiler::ir::{Material, Scene};
use kiln_compiler::progress::Progress;
use kiln_compiler::settings::Settings;
use kiln_format::sections::Vertex;

/// The shared scene folder (`../shared/scenes` beside the checkout), if present.
pub fn shared_scenes() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes");
    dir.is_dir().then_some(dir)
}

/// A scene of the given triangles (one grey Lambertian material, flat normals; a Lambertian
/// scene needs no BRDF table, which keeps compiling thousands of test scenes quick).
pub fn scene_of(tris: &[[Vec3; 3]]) -> Scene {
    let mut s = Scene { name: "test".into(), ..Default::default() };
    s.materials
        .push(Material { name: "m".into(), gpu: kiln_compiler::import::demo::lambert_material([0.5; 3]) });
    for t in tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or(Vec3::Z);
        let base = s.vertices.len() as u32;
        for p in t {
            s.vertices.push(Vertex { position: p.to_array(), normal: n.to_array() });
        }
        s.triangles.push([base, base + 1, base + 2]);
        s.triangle_materials.push(0);
    }
    s
}

/// Compiles a scene in memory (as `kiln compile` would) and returns the file's bytes.
pub fn compile(scene: Scene, settings: Settings) -> Vec<u8> {
    let loaded = kiln_compiler::pipeline::finish(scene, settings, "test", false, true, Instant::now())
        .expect("valid scene");
    let plan: &Plan = &loaded.plan;
    let baked =
        bake::bake(&loaded.scene, &loaded.settings, plan, Vec::new(), &Progress::hidden()).expect("bake");
    bake::to_bytes(&baked).expect("write")
}
