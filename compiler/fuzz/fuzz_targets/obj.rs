//! Fuzzes the OBJ/MTL importer: the bytes before the first line `#mtl` are the OBJ, those after
//! it its MTL library `scene.mtl`; they must import, validate and plan or fail with an error.
#![no_main]

use kiln_compiler::untrusted::{Case, Kind, plan};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("kiln-fuzz-obj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let split = data.windows(5).position(|w| w == b"#mtl\n");
    let (obj, mtl) = match split {
        Some(i) => (&data[..i], &data[i + 5..]),
        None => (data, &[][..]),
    };
    let _ = plan(&dir, &Case { kind: Kind::Obj, main: obj, mtl, sidecar: None });
});
