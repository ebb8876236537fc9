//! Links the C++ runtime: `intel_tex_2`'s prebuilt Linux archive holds a C++ object (its ASTC
//! helper) that the linker pulls in with the BC kernels and that needs `__gxx_personality_v0`,
//! and the crate does not link the runtime itself.

fn main() {
    let target = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if target == "linux" {
        println!("cargo:rustc-link-lib=stdc++");
    }
}
