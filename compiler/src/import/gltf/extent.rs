//! The extent a glTF scene declares, for choosing the origin its positions are stored from.

use glam::{DMat4, DVec3};

use crate::import::geometry::Extent;

/// The extent of the meshes the nodes place, from their POSITION accessors' `min` and `max`
/// (which glTF requires) under each node's transform: all [`rebase_origin`] needs, before any
/// buffer is read. Skins and morph targets are not applied and a file may misstate its bounds;
/// either only costs precision, never correctness (positions are relative to whatever origin).
///
/// [`rebase_origin`]: crate::import::geometry::rebase_origin
pub(super) fn declared_extent(placed: &[(::gltf::Node, DMat4)]) -> Extent {
    let mut extent = Extent::default();
    let corner = |v: Option<::gltf::json::Value>| -> Option<DVec3> {
        let a = v?.as_array()?.iter().map(|c| c.as_f64()).collect::<Option<Vec<f64>>>()?;
        (a.len() == 3).then(|| DVec3::new(a[0], a[1], a[2]))
    };
    for (node, world) in placed {
        let Some(mesh) = node.mesh() else { continue };
        for prim in mesh.primitives() {
            let Some(acc) = prim.get(&::gltf::Semantic::Positions) else { continue };
            match (corner(acc.min()), corner(acc.max())) {
                (Some(lo), Some(hi)) => {
                    for k in 0..8 {
                        let pick = |bit: usize, a: f64, b: f64| if k >> bit & 1 == 0 { a } else { b };
                        let c = DVec3::new(pick(0, lo.x, hi.x), pick(1, lo.y, hi.y), pick(2, lo.z, hi.z));
                        extent.add(world.transform_point3(c));
                    }
                }
                _ => extent.add(world.transform_point3(DVec3::ZERO)),
            }
        }
    }
    extent
}
