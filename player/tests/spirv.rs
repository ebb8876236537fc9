//! The SPIR-V the player embeds (each `shaders/<source>.spv`, beside its source) must be what
//! `glslc` makes of the committed GLSL today: each shader is recompiled with
//! `shaders/build.sh`'s flags and compared word for word (except the generator word of the
//! header, which names the glslc build). Without glslc that test says so and passes, unless
//! `KILN_REQUIRE_GLSLC` is set (as `.ci/run` does). Every source must have its `.spv` and every
//! `.spv` a source.

use std::path::{Path, PathBuf};
use std::process::Command;

use kiln_test_support::{glslc, require};

fn shaders() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders")
}

fn words(bytes: &[u8]) -> Vec<u32> {
    bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// Every file under `shaders/` whose name ends in one of `extensions`, as `/`-separated paths
/// under `shaders/`, skipping `common/` (included GLSL, no stages).
fn files(extensions: &[&str]) -> Vec<String> {
    fn walk(dir: &Path, rel: &str, extensions: &[&str], found: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_str().unwrap().to_owned();
            let rel = if rel.is_empty() { name } else { format!("{rel}/{name}") };
            if path.is_dir() {
                if rel != "common" {
                    walk(&path, &rel, extensions, found);
                }
            } else if path.extension().and_then(|e| e.to_str()).is_some_and(|e| extensions.contains(&e)) {
                found.push(rel);
            }
        }
    }
    let mut found = Vec::new();
    walk(&shaders(), "", extensions, &mut found);
    found.sort();
    found
}

/// Every shader source as `shaders/build.sh` finds them: files with a stage extension in a
/// folder (not at the top) other than `common/`.
fn sources() -> Vec<String> {
    files(&["vert", "frag", "comp", "rgen", "rmiss", "rchit"])
        .into_iter()
        .filter(|s| s.contains('/'))
        .collect()
}

#[test]
fn embedded_spirv_is_built_from_the_committed_sources() {
    require!(glslc());
    let dir = tempfile::tempdir().unwrap();
    for source in sources() {
        let embedded = &std::fs::read(shaders().join(format!("{source}.spv")))
            .unwrap_or_else(|e| panic!("shaders/{source}.spv: {e}: run shaders/build.sh"));
        let out = dir.path().join("out.spv");
        let status = Command::new("glslc")
            .args(["--target-env=vulkan1.3", "-O", "-o"])
            .arg(&out)
            .arg(shaders().join(&source))
            .status()
            .unwrap();
        assert!(status.success(), "glslc failed on {source}");
        let fresh = words(&std::fs::read(&out).unwrap());
        let mut committed = words(embedded);
        assert!(
            committed.len() > 5 && committed[0] == 0x0723_0203,
            "{source}: the embedded bytes are not SPIR-V"
        );
        // Word 2 is the generator (tool and its version); everything else must match.
        committed[2] = fresh[2];
        assert!(
            committed == fresh,
            "shaders/{source}.spv is stale: run shaders/build.sh and commit the result"
        );
    }
}

#[test]
fn every_source_has_its_spirv_and_every_spirv_a_source() {
    let found = sources();
    assert!(found.len() >= 40, "only {} shader sources under {}", found.len(), shaders().display());
    let spirv = files(&["spv"]);
    for s in &found {
        assert!(spirv.contains(&format!("{s}.spv")), "shaders/{s} has no {s}.spv: run shaders/build.sh");
    }
    // shaders/build.sh removes stale outputs; a committed one would be embedded by nothing.
    for f in &spirv {
        let source = f.strip_suffix(".spv").unwrap();
        assert!(found.iter().any(|s| s == source), "shaders/{f} has no source: run shaders/build.sh");
    }
}
