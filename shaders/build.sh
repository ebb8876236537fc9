#!/usr/bin/env bash
# Compiles every shader under shaders/ to shaders/spirv/ with glslc (Debian package `glslc`).
# The player embeds the .spv files, so a machine with only the Rust toolchain builds it; the test
# `player/tests/spirv.rs` recompiles the sources and fails if the committed SPIR-V differs.
set -euo pipefail
cd "$(dirname "$0")"
for src in gbuffer/gbuffer.vert gbuffer/gbuffer.frag lighting/direct.comp post/tonemap.comp trace/rays.comp reference/pathtrace.comp rt/shadows.comp rt/ao.comp rt/reflections.comp rt/reflection_shadows.comp gbuffer/visibility.frag gbuffer/visibility_opaque.frag gbuffer/resolve.comp peer/trace.rgen peer/trace.rmiss peer/trace.rchit; do
    out="spirv/$(basename "$src").spv"
    glslc --target-env=vulkan1.3 -O -o "$out" "$src"
done
