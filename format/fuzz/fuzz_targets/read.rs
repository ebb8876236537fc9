//! Fuzzes the reader: any byte string must open or fail with an error, and an opened file's
//! manifest, sections and scene view must be readable without panics.
#![no_main]

use kiln_format::{Checksums, KilnFile, SceneView};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for policy in [Checksums::Deferred, Checksums::Eager] {
        let Ok(file) = KilnFile::from_bytes(data, policy) else { continue };
        let _ = file.manifest();
        for s in file.sections() {
            let _ = file.section_bytes(s);
        }
        if let Ok(view) = SceneView::new(&file) {
            // A validated view must be safe to walk.
            let t = kiln_format::query::IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
            let q = kiln_format::query::BvhQuery::new(view.bvh, &t);
            let ray = kiln_format::query::Ray::new(glam::Vec3::ZERO, glam::Vec3::ONE.normalize(), 0.0, f32::INFINITY);
            let _ = q.closest_hit(&ray);
        }
    }
});
