//! Times the driver's compilation of variants of the direct-light shader (`direct.comp`, the
//! pass whose pipeline bounds the default first frame on a cold cache): each SPIR-V file given
//! (or the embedded one, `-`) is made into a compute pipeline with the pass's bindings and no
//! pipeline cache, with every path (no specialization constants) or, with `--default`,
//! specialised for the default techniques and no rect lights; the milliseconds are printed. Run one process per variant with the driver's own shader cache off
//! (`__GL_SHADER_DISK_CACHE=0` on NVIDIA), so that nothing is reused.
//!
//! `cargo run --release -p kiln-player --example direct_compile -- [--default] A.spv|- [B.spv ...]`

use kiln_player::gpu::{Gpu, GpuOptions};
use kiln_player::render::passes::direct::DirectPass;
use kiln_player::render::passes::kernel::Kernel;
use kiln_player::render::{Techniques, spirv};

fn main() {
    let mut paths: Vec<String> = std::env::args().skip(1).collect();
    let default = paths.first().is_some_and(|a| a == "--default");
    if default {
        paths.remove(0);
    }
    let constants: Vec<u32> = if default {
        DirectPass::constants(Techniques::default().flags(), false, false).to_vec()
    } else {
        Vec::new()
    };
    if paths.is_empty() {
        eprintln!("usage: direct_compile A.spv [B.spv ...]");
        std::process::exit(2);
    }
    let options = GpuOptions { pipeline_cache: None, ..GpuOptions::default() };
    let gpu = Gpu::new(&options).unwrap_or_else(|e| {
        eprintln!("no device: {e}");
        std::process::exit(1)
    });
    for path in &paths {
        let code = if path == "-" {
            std::fs::read(spirv::shader_dir().join("lighting/direct.comp.spv")).expect("the committed SPIR-V")
        } else {
            std::fs::read(path).unwrap_or_else(|e| {
                eprintln!("{path}: {e}");
                std::process::exit(1)
            })
        };
        let t = std::time::Instant::now();
        match Kernel::specialized(
            &gpu,
            &DirectPass::bindings(),
            &code,
            kiln_player::render::passes::direct::PUSH_BYTES,
            &constants,
        ) {
            Ok(_kernel) => {
                let how = if default { "specialised for the defaults" } else { "every path" };
                println!("{path} {how} {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
            }
            Err(e) => println!("{path} failed: {e}"),
        }
    }
}
