//! SPIR-V of the shaders, built from `shaders/` by `shaders/build.sh` (checked by
//! `player/tests/spirv.rs`). A shader's SPIR-V sits beside its source: `gtao/gtao.comp` is
//! `shaders/gtao/gtao.comp.spv`, so a pass names its shader once, by its source, and a new
//! technique's shaders need no entry anywhere else.

/// The embedded SPIR-V of the shader whose source is `shaders/<SOURCE>`
/// (`shader!("gtao/gtao.comp")`).
macro_rules! shader {
    ($source:literal) => {
        include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/../shaders/", $source, ".spv")).as_slice()
    };
}
pub(crate) use shader;

/// The folder holding the shader sources and their SPIR-V.
pub fn shader_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders")
}

/// The file extensions of shader sources (a stage each).
pub const STAGES: [&str; 6] = ["vert", "frag", "comp", "rgen", "rmiss", "rchit"];

/// Every shader source under [`shader_dir`] as `shaders/build.sh` finds them (files with a
/// stage extension in a folder other than `common/`), as `/`-separated paths, sorted.
pub fn sources() -> std::io::Result<Vec<String>> {
    fn walk(dir: &std::path::Path, rel: &str, found: &mut Vec<String>) -> std::io::Result<()> {
        for entry in std::fs::read_dir(dir)? {
            let path = entry?.path();
            let Some(name) = path.file_name().and_then(|n| n.to_str()) else { continue };
            let rel = if rel.is_empty() { name.to_owned() } else { format!("{rel}/{name}") };
            if path.is_dir() {
                if rel != "common" {
                    walk(&path, &rel, found)?;
                }
            } else if rel.contains('/')
                && path.extension().and_then(|e| e.to_str()).is_some_and(|e| STAGES.contains(&e))
            {
                found.push(rel);
            }
        }
        Ok(())
    }
    let mut found = Vec::new();
    walk(&shader_dir(), "", &mut found)?;
    found.sort();
    Ok(found)
}
