//! The SPIR-V the player embeds (`shaders/spirv/`) must be what `glslc` makes of the committed
//! GLSL today: each shader is recompiled with `shaders/build.sh`'s flags and compared word for
//! word (except the generator word of the header, which names the glslc build). Without glslc
//! that test says so and passes, unless `KILN_REQUIRE_GLSLC` is set (as `.ci/run` does).
//! The sources, the embedded table and `shaders/spirv/` must also agree one to one, under
//! build.sh's naming rule (`rt/ao.comp` -> `spirv/rt.ao.comp.spv`), with no two sources sharing
//! an output name.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

use kiln_player::render::spirv;
use kiln_test_support::{glslc, require};

fn shaders() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders")
}

fn words(bytes: &[u8]) -> Vec<u32> {
    bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// The file under `shaders/spirv/` that `shaders/build.sh` compiles `source` to: its path under
/// `shaders/` with each `/` replaced by `.`, plus `.spv`.
fn output_name(source: &str) -> String {
    format!("{}.spv", source.replace('/', "."))
}

/// Every shader source under `shaders/` as `shaders/build.sh` finds them: files with a stage
/// extension in any folder but `common/` and `spirv/`, as `/`-separated paths under `shaders/`.
fn sources() -> Vec<String> {
    fn walk(dir: &Path, rel: &str, found: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_str().unwrap().to_owned();
            let rel = if rel.is_empty() { name } else { format!("{rel}/{name}") };
            if path.is_dir() {
                if rel != "common" && rel != "spirv" {
                    walk(&path, &rel, found);
                }
            } else if rel.contains('/')
                && matches!(
                    path.extension().and_then(|e| e.to_str()),
                    Some("vert" | "frag" | "comp" | "rgen" | "rmiss" | "rchit")
                )
            {
                found.push(rel);
            }
        }
    }
    let mut found = Vec::new();
    walk(&shaders(), "", &mut found);
    found.sort();
    found
}

/// Sources that would compile to the same output name: (output, the sources).
fn collisions(sources: &[String]) -> Vec<(String, Vec<String>)> {
    let mut by_output: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for s in sources {
        by_output.entry(output_name(s)).or_default().push(s.clone());
    }
    by_output.into_iter().filter(|(_, s)| s.len() > 1).collect()
}

#[test]
fn embedded_spirv_is_built_from_the_committed_sources() {
    require!(glslc());
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
fn no_two_sources_share_an_output_name() {
    let found = collisions(&sources());
    assert!(found.is_empty(), "sources that would compile to the same shaders/spirv/ file: {found:?}");
    // The check sees the clash that naming by path allows: a dot in a folder or file name.
    let planted = collisions(&["rt/x.y.comp".to_owned(), "rt.x/y.comp".to_owned(), "rt/ao.comp".to_owned()]);
    assert_eq!(
        planted,
        [("rt.x.y.comp.spv".to_owned(), vec!["rt/x.y.comp".to_owned(), "rt.x/y.comp".to_owned()])]
    );
}

#[test]
fn every_source_is_embedded_and_every_embedded_shader_has_a_source() {
    let found = sources();
    assert!(!found.is_empty(), "no shader sources under {}", shaders().display());
    let embedded: BTreeSet<&str> = spirv::ALL.iter().map(|(s, _)| *s).collect();
    assert_eq!(embedded.len(), spirv::ALL.len(), "a source is embedded twice in render/spirv.rs");
    for s in &found {
        assert!(embedded.contains(s.as_str()), "the player does not embed shaders/{s} (render/spirv.rs)");
    }
    for (s, bytes) in spirv::ALL {
        assert!(found.iter().any(|f| f == s), "render/spirv.rs embeds {s}, which is not a shader source");
        let file = shaders().join("spirv").join(output_name(s));
        let on_disk = std::fs::read(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        assert!(on_disk == *bytes, "render/spirv.rs embeds other bytes for {s} than {}", file.display());
    }
    // shaders/build.sh removes stale outputs; a committed one would be embedded by nothing.
    let outputs: BTreeSet<String> = found.iter().map(|s| output_name(s)).collect();
    for entry in std::fs::read_dir(shaders().join("spirv")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        assert!(outputs.contains(&name), "shaders/spirv/{name} has no source: run shaders/build.sh");
    }
}
