//! What the player's integration tests share: the Vulkan check and `kiln` run in process.

/// Whether a Vulkan device is here; without one a test says so and passes, unless
/// `KILN_REQUIRE_VULKAN` is set (as `.ci/run` does).
pub fn vulkan() -> bool {
    if kiln_player::gpu::list_devices().map_or(true, |d| d.is_empty()) {
        assert!(
            std::env::var_os("KILN_REQUIRE_VULKAN").is_none(),
            "no Vulkan device but KILN_REQUIRE_VULKAN is set"
        );
        eprintln!("skipping: no Vulkan device");
        return false;
    }
    true
}

/// Runs `kiln ARGS` in this process (the compiler is a dev-dependency); panics if it fails.
pub fn kiln(args: &[&str]) {
    use clap::Parser;
    let cli = kiln_compiler::cli::Cli::parse_from(std::iter::once("kiln").chain(args.iter().copied()));
    kiln_compiler::commands::run(cli).unwrap();
}
