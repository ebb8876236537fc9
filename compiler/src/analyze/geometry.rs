//! What the plan and the bake both derive from a validated scene's geometry, computed once: the
//! world-space triangles, the bounds and, on first use, the voxel grid.

use std::sync::{Arc, Mutex, OnceLock};

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
    /// The voxel grid the bake uses and the resolution it was built at.
    voxels: OnceLock<(u32, Arc<Voxels>)>,
    /// The last grid the plan's size search built, kept so that the bake reuses the one chosen.
    trial: Mutex<Option<(u32, Arc<Voxels>)>>,
}

impl SceneGeometry {
    /// The geometry of a validated scene.
    pub fn new(scene: &Scene) -> SceneGeometry {
        SceneGeometry {
            bounds: bounds(scene),
            corners: scene.triangles.iter().map(|t| t.map(|i| scene.vertices[i as usize].position)).collect(),
            voxels: OnceLock::new(),
            trial: Mutex::new(None),
        }
    }

    /// The scene voxelized at `res` cells along the longest axis: the grid the bake uses, built
    /// once (taken from the plan's last trial when it has this resolution).
    pub fn voxels(&self, res: u32) -> &Voxels {
        let (built_at, voxels) = self.voxels.get_or_init(|| (res, self.trial_voxels(res)));
        assert_eq!(*built_at, res, "the plan and the bake asked for voxel grids of different resolutions");
        voxels
    }

    /// The scene voxelized at `res` for a size estimate: the bake's grid or the last trial when
    /// either has this resolution, otherwise built now (replacing the last trial).
    pub fn trial_voxels(&self, res: u32) -> Arc<Voxels> {
        if let Some((r, v)) = self.voxels.get()
            && *r == res
        {
            return v.clone();
        }
        let mut trial = self.trial.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((r, v)) = trial.as_ref()
            && *r == res
        {
            return v.clone();
        }
        let v = Arc::new(Voxels::new(&self.bounds, res, &self.corners));
        *trial = Some((res, v.clone()));
        v
    }
}
