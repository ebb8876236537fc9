//! Process-wide calls into the C library, here because `unsafe` lives only under `gpu/`
//! (`tests/fence.rs`); neither touches Vulkan.

/// Lets a closed standard output end the process quietly, as it ends a C tool: `kiln-bench
/// --diff A B | head -1`, `kiln-play --bench … | head`. Rust ignores SIGPIPE, so the next
/// `println!` after the reader went away would panic with "failed printing to stdout: Broken
/// pipe" and a backtrace. Called first in `main`.
pub fn quiet_on_closed_stdout() {
    #[cfg(unix)]
    // SAFETY: restores the signal's default disposition before any thread is started; no
    // handler function is installed.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Hands the memory a closed session freed back to the system. Each session's driver threads
/// (lavapipe starts its own per device) allocate from glibc arenas of their own, which keep
/// freed memory mapped: a sweep of a few hundred sessions on lavapipe grew to 0.7–1 GB resident
/// at 64 × 64 (10.7 GB once, with more configurations) with under 100 MB actually allocated
/// (heaptrack; docs/benchmarks/sweep/memory-lavapipe.md). `malloc_trim` returns every arena's
/// free pages.
pub fn release_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only walks glibc's own arenas; it takes no pointers.
    unsafe {
        libc::malloc_trim(0);
    }
}
