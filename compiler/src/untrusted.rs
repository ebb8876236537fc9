//! Untrusted bytes through the compile as `kiln compile` runs it: written as a scene (and its
//! MTL library and sidecar) into a folder, imported with the command line's default limits and
//! confinement, validated, planned and, on request, baked. The fuzz targets (`compiler/fuzz`)
//! and the mutation test (`compiler/tests/mutations.rs`) feed it; any panic or abort on the way
//! is a bug, any `Err` an accepted outcome.

use std::path::Path;

use crate::cli::{BakeArgs, LimitArgs, SceneArgs};
use crate::exit::{CliError, CliResult};
use crate::pipeline::{self, Loaded};

/// The kind of the main file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// glTF JSON, written as `scene.gltf`.
    Gltf,
    /// Binary glTF, written as `scene.glb`.
    Glb,
    /// OBJ, written as `scene.obj`; the MTL bytes as `scene.mtl`.
    Obj,
}

/// One case: the main file, the MTL library an OBJ may name (`mtllib scene.mtl`), and a sidecar.
#[derive(Debug, Clone, Copy)]
pub struct Case<'a> {
    /// What `main` is.
    pub kind: Kind,
    /// The scene file's bytes.
    pub main: &'a [u8],
    /// Written as `scene.mtl` (OBJ only).
    pub mtl: &'a [u8],
    /// Written as `scene.toml` and passed with `-c` when present.
    pub sidecar: Option<&'a [u8]>,
}

/// The largest file a case may read: small, so that a case's memory stays bounded by what its
/// settings ask (which the plan's limits bound).
const MAX_FILE: u64 = 64 << 20;

/// The largest image side a case decodes.
const MAX_IMAGE_SIDE: u32 = 4096;

/// Writes `case` into `dir` (which it owns) and imports, validates and plans it as `kiln compile`
/// would (confined to `dir`, default bake limits), quietly.
pub fn plan(dir: &Path, case: &Case) -> CliResult<Loaded> {
    let name = match case.kind {
        Kind::Gltf => "scene.gltf",
        Kind::Glb => "scene.glb",
        Kind::Obj => "scene.obj",
    };
    let write = |file: &str, bytes: &[u8]| {
        std::fs::write(dir.join(file), bytes).map_err(|e| CliError::io(format!("{file}: {e}")))
    };
    write(name, case.main)?;
    if case.kind == Kind::Obj {
        write("scene.mtl", case.mtl)?;
    }
    let config = match case.sidecar {
        Some(s) => {
            write("scene.toml", s)?;
            Some(dir.join("scene.toml"))
        }
        None => None,
    };
    let args = SceneArgs {
        input: dir.join(name),
        config,
        bake: BakeArgs::default(),
        strict: false,
        warning_levels: Vec::new(),
        max_file_size: Some(MAX_FILE),
        max_image_side: Some(MAX_IMAGE_SIDE),
        limits: LimitArgs::default(),
    };
    pipeline::load(&args, true)
}

/// Bakes a planned case to the bytes of its file.
pub fn bake(loaded: &Loaded) -> CliResult<Vec<u8>> {
    pipeline::bake_to_bytes(loaded)
}
