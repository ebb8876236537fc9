//! The SPIR-V the compiler embeds for its GPU bake (`compiler/shaders/spirv/`) must be what
//! `glslc` makes of the committed GLSL today, with `compiler/shaders/build.sh`'s flags: each
//! kernel is recompiled and compared word for word (but for the header's generator word, which
//! names the glslc build), and every kernel has its SPIR-V and no SPIR-V lacks its kernel.
//! Without glslc the test says so and passes, unless `KILN_REQUIRE_GLSLC` is set (as `.ci/run`
//! does).

use std::path::{Path, PathBuf};
use std::process::Command;

use kiln_test_support::{glslc, require};

fn shaders() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders")
}

fn words(bytes: &[u8]) -> Vec<u32> {
    bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

fn names(dir: &Path, ext: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(ext))
        .collect();
    v.sort();
    v
}

#[test]
fn committed_bake_spirv_is_compiled_from_the_glsl() {
    let kernels = names(&shaders(), ".comp");
    let spirv: Vec<String> = names(&shaders().join("spirv"), ".spv");
    let expected: Vec<String> = kernels.iter().map(|k| format!("{k}.spv")).collect();
    assert_eq!(
        spirv, expected,
        "shaders/spirv/ must hold exactly one .spv per kernel: run compiler/shaders/build.sh"
    );
    require!(glslc());
    let out = std::env::temp_dir().join(format!("kiln-bake-spirv-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    for k in &kernels {
        let fresh_path = out.join(format!("{k}.spv"));
        let status = Command::new("glslc")
            .args(["--target-env=vulkan1.2", "-O", "-o"])
            .arg(&fresh_path)
            .arg(shaders().join(k))
            .status()
            .unwrap();
        assert!(status.success(), "glslc failed on {k}");
        let fresh = words(&std::fs::read(&fresh_path).unwrap());
        let mut committed = words(&std::fs::read(shaders().join("spirv").join(format!("{k}.spv"))).unwrap());
        assert!(committed.len() > 5 && fresh.len() > 5, "{k}: not SPIR-V");
        // Word 2 is the generator (tool and its version); everything else must match.
        committed[2] = fresh[2];
        assert!(committed == fresh, "shaders/spirv/{k}.spv is stale: run compiler/shaders/build.sh");
    }
    let _ = std::fs::remove_dir_all(&out);
}
