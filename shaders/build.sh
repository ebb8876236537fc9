#!/usr/bin/env bash
# Compiles every shader under shaders/ with glslc (Debian package `glslc`), each to a .spv file
# beside its source: gtao/gtao.comp -> gtao/gtao.comp.spv. The player embeds the .spv files
# (player/src/render/spirv.rs, `shader!("gtao/gtao.comp")`), so a machine with only the Rust
# toolchain builds it; the test `player/tests/spirv.rs` recompiles the sources and fails if the
# committed SPIR-V differs, or if a source has no .spv or a .spv no source.
#
# Sources: every .vert, .frag, .comp, .rgen, .rmiss and .rchit file in a pass folder (any folder
# but common/). .spv files that no source produces are removed.
set -euo pipefail
cd "$(dirname "$0")"

sources=()
while IFS= read -r -d '' src; do
    sources+=("${src#./}")
done < <(find . -mindepth 2 -type f \
    \( -name '*.vert' -o -name '*.frag' -o -name '*.comp' -o -name '*.rgen' -o -name '*.rmiss' -o -name '*.rchit' \) \
    -not -path './common/*' -print0 | LC_ALL=C sort -z)

declare -A is_output
for src in "${sources[@]}"; do
    glslc --target-env=vulkan1.3 -O -o "$src.spv" "$src"
    is_output["$src.spv"]=1
done

while IFS= read -r -d '' spv; do
    spv="${spv#./}"
    if [[ -z "${is_output[$spv]:-}" ]]; then
        rm -- "$spv"
        echo "removed stale shaders/$spv (no source produces it)"
    fi
done < <(find . -type f -name '*.spv' -print0)
