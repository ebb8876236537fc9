//! Analysis: final validation of the imported scene, its geometry as the plan and the bake share
//! it, and the plan of what to bake.

pub mod budget;
pub mod geometry;
pub mod limits;
pub mod plan;
pub mod validate;
