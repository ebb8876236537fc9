//! Analysis: final validation of the imported scene, and the plan of what to bake.

pub mod plan;
pub mod validate;
