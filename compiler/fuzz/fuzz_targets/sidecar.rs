//! Fuzzes the sidecar: any bytes as the TOML sidecar of a small lit OBJ scene (two named
//! materials, so that `[material."NAME"]` tables apply) must apply, validate and plan or fail
//! with an error.
#![no_main]

use kiln_compiler::untrusted::{Case, Kind, plan};
use libfuzzer_sys::fuzz_target;

const OBJ: &[u8] = b"mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl floor\nf 1 2 3\nusemtl light\nf 1 2 4\nf 1 3 4\n";
const MTL: &[u8] = b"newmtl floor\nKd 0.8 0.8 0.8\nnewmtl light\nKd 0 0 0\nKe 5 5 5\n";

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("kiln-fuzz-sidecar-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let _ = plan(&dir, &Case { kind: Kind::Obj, main: OBJ, mtl: MTL, sidecar: Some(data) });
});
