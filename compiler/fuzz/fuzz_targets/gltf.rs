//! Fuzzes the glTF importer: any bytes, as a `.glb` when they start with its magic and as a
//! `.gltf` otherwise, must import, validate and plan or fail with an error; never a panic,
//! abort, hang or unbounded allocation (run with `-timeout=10 -rss_limit_mb=2048`).
#![no_main]

use kiln_compiler::untrusted::{Case, Kind, plan};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("kiln-fuzz-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let kind = if data.starts_with(b"glTF") { Kind::Glb } else { Kind::Gltf };
    let _ = plan(&dir, &Case { kind, main: data, mtl: &[], sidecar: None });
});
