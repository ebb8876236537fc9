//! Importers: glTF 2.0 and OBJ/MTL into the scene IR, the TOML sidecar on top, and the
//! built-in demo scene. This is the only place loader types appear.

pub mod demo;
pub mod environment;
pub mod files;
pub(crate) mod geometry;
mod gltf;
mod images;
mod mtl;
mod obj;
pub mod preetham;
pub mod sidecar;

use std::path::{Path, PathBuf};

use crate::exit::{CliError, CliResult, Exit};
use crate::ir::Scene;
use crate::settings::Normals;

pub use geometry::MAX_COORDINATE;

/// Input formats kiln reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputFormat {
    /// glTF 2.0, JSON (`.gltf`).
    Gltf,
    /// glTF 2.0, binary (`.glb`).
    Glb,
    /// Wavefront OBJ with MTL.
    Obj,
}

impl InputFormat {
    /// The format of `path`, judged by its extension.
    pub fn of(path: &Path) -> CliResult<InputFormat> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("gltf") => Ok(InputFormat::Gltf),
            Some("glb") => Ok(InputFormat::Glb),
            Some("obj") => Ok(InputFormat::Obj),
            _ => Err(CliError::new(
                Exit::Unsupported,
                format!("{}: unsupported input format (kiln reads .gltf, .glb and .obj)", path.display()),
            )),
        }
    }
}

/// Reads a whole input file, recording it as an input.
pub(crate) fn read_input(path: &Path, inputs: &mut Vec<PathBuf>) -> CliResult<Vec<u8>> {
    let bytes = files::read_bounded(path).map_err(CliError::io)?;
    if !inputs.iter().any(|p| p == path) {
        inputs.push(path.to_path_buf());
    }
    Ok(bytes)
}

/// Imports `path` into a new scene (geometry, materials, textures, asset lights and cameras),
/// with normals made as the format says where the asset gives none.
pub fn import(path: &Path) -> CliResult<Scene> {
    import_with(path, Normals::Asset)
}

/// Imports `path`, making normals by `normals` where the asset gives none.
pub fn import_with(path: &Path, normals: Normals) -> CliResult<Scene> {
    let format = InputFormat::of(path)?;
    let mut scene = Scene {
        name: path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into()),
        ..Default::default()
    };
    match format {
        InputFormat::Gltf | InputFormat::Glb => gltf::import(path, &mut scene, normals)?,
        InputFormat::Obj => obj::import(path, &mut scene, normals)?,
    }
    Ok(scene)
}
