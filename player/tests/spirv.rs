//! The SPIR-V the player embeds (`shaders/spirv/`) must be what `glslc` makes of the committed
//! GLSL today: each shader is recompiled with `shaders/build.sh`'s flags and compared word for
//! word (except the generator word of the header, which names the glslc build). Without glslc
//! the test says so and passes, unless `KILN_REQUIRE_GLSLC` is set (as `.ci/run` does).

use std::path::{Path, PathBuf};
use std::process::Command;

use kiln_player::render::spirv;

fn shaders() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders")
}

fn words(bytes: &[u8]) -> Vec<u32> {
    bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

#[test]
fn embedded_spirv_is_built_from_the_committed_sources() {
    let version = Command::new("glslc").arg("--version").output();
    if version.as_ref().map_or(true, |o| !o.status.success()) {
        assert!(
            std::env::var_os("KILN_REQUIRE_GLSLC").is_none(),
            "glslc is not installed but KILN_REQUIRE_GLSLC is set"
        );
        eprintln!("skipping: glslc is not installed (Debian: glslc)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (source, embedded) in spirv::ALL {
        let out = dir.path().join("out.spv");
        let status = Command::new("glslc")
            .args(["--target-env=vulkan1.3", "-O", "-o"])
            .arg(&out)
            .arg(shaders().join(source))
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
            "shaders/spirv/ for {source} is stale: run shaders/build.sh and commit the result"
        );
    }
}

#[test]
fn every_shader_source_is_built_and_embedded() {
    let build = std::fs::read_to_string(shaders().join("build.sh")).unwrap();
    let mut found = Vec::new();
    for folder in std::fs::read_dir(shaders()).unwrap() {
        let folder = folder.unwrap().path();
        if !folder.is_dir() {
            continue;
        }
        for f in std::fs::read_dir(&folder).unwrap() {
            let f = f.unwrap().path();
            if matches!(
                f.extension().and_then(|e| e.to_str()),
                Some("vert" | "frag" | "comp" | "rgen" | "rmiss" | "rchit")
            ) {
                let rel = format!(
                    "{}/{}",
                    folder.file_name().unwrap().to_str().unwrap(),
                    f.file_name().unwrap().to_str().unwrap()
                );
                assert!(build.contains(&rel), "shaders/build.sh does not compile {rel}");
                assert!(spirv::ALL.iter().any(|(s, _)| *s == rel), "the player does not embed {rel}");
                found.push(rel);
            }
        }
    }
    assert_eq!(found.len(), spirv::ALL.len(), "embedded shaders without a source: {found:?}");
}
