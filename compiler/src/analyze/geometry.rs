//! What the plan and the bake both derive from a validated scene's geometry, computed once: the
//! world-space triangles, the bounds and, on first use, the voxel grid.

use std::sync::OnceLock;

use kiln_format::manifest::Bounds;

use crate::analyze::validate::bounds;
use crate::bake::linespace::voxelize::Voxels;
use crate::ir::Scene;

/// A scene's geometry in its own triangle order.
#[derive(Debug)]
pub struct SceneGeometry {
    /// Bounds of every vertex a triangle uses.
    pub bounds: Bounds,
    /// World-space corners of every triangle.
    pub corners: Vec<[[f32; 3]; 3]>,
    /// The voxel grid and the resolution it was built at.
    voxels: OnceLock<(u32, Voxels)>,
}

impl SceneGeometry {
    /// The geometry of a validated scene.
    pub fn new(scene: &Scene) -> SceneGeometry {
        SceneGeometry {
            bounds: bounds(scene),
            corners: scene.triangles.iter().map(|t| t.map(|i| scene.vertices[i as usize].position)).collect(),
            voxels: OnceLock::new(),
        }
    }

    /// The scene voxelized at `res` cells along the longest axis: by the plan when it estimates
    /// the line space's size, otherwise by the voxel-grid stage; never twice.
    pub fn voxels(&self, res: u32) -> &Voxels {
        let (built_at, voxels) =
            self.voxels.get_or_init(|| (res, Voxels::new(&self.bounds, res, &self.corners)));
        assert_eq!(*built_at, res, "the plan and the bake asked for voxel grids of different resolutions");
        voxels
    }
}
