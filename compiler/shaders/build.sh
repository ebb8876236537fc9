#!/usr/bin/env bash
# Compiles the compiler's GPU bake kernels (compiler/shaders/*.comp) to compiler/shaders/spirv/
# with glslc (Debian package `glslc`), for Vulkan 1.2 (what kiln-gpubake asks of a device). The
# compiler embeds the .spv files, so a machine with only the Rust toolchain builds it; the test
# `compiler/tests/bake_spirv.rs` recompiles the sources and fails if the committed SPIR-V differs.
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p spirv
for src in *.comp; do
    glslc --target-env=vulkan1.2 -O -o "spirv/$src.spv" "$src"
done
