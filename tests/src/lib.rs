//! Workspace-level integration tests (see `tests/*.rs`); this library holds their shared helpers.

use std::path::PathBuf;

/// The shared scene folder (`../shared/scenes` beside the checkout), if present.
pub fn shared_scenes() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes");
    dir.is_dir().then_some(dir)
}
