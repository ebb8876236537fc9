#!/usr/bin/env bash
# Compiles every shader under shaders/ to shaders/spirv/ with glslc (Debian package `glslc`).
# The player embeds the .spv files (player/src/render/spirv.rs), so a machine with only the Rust
# toolchain builds it; the test `player/tests/spirv.rs` recompiles the sources and fails if the
# committed SPIR-V differs, or if a source and the embedded table disagree.
#
# Sources: every .vert, .frag, .comp, .rgen, .rmiss and .rchit file in a pass folder (any folder
# but common/ and spirv/). Output named by path: rt/ao.comp -> spirv/rt.ao.comp.spv (the path
# with each '/' replaced by '.'). Two sources that would get the same name are an error, found
# before anything is compiled; .spv files that no source produces are removed.
set -euo pipefail
cd "$(dirname "$0")"

sources=()
while IFS= read -r -d '' src; do
    sources+=("${src#./}")
done < <(find . -mindepth 2 -type f \
    \( -name '*.vert' -o -name '*.frag' -o -name '*.comp' -o -name '*.rgen' -o -name '*.rmiss' -o -name '*.rchit' \) \
    -not -path './common/*' -not -path './spirv/*' -print0 | LC_ALL=C sort -z)

declare -A source_of
for src in "${sources[@]}"; do
    out="spirv/${src//\//.}.spv"
    if [[ -n "${source_of[$out]:-}" ]]; then
        echo "Error: shaders/$src and shaders/${source_of[$out]} would both compile to shaders/$out; rename one" >&2
        exit 1
    fi
    source_of[$out]=$src
done

mkdir -p spirv
for src in "${sources[@]}"; do
    glslc --target-env=vulkan1.3 -O -o "spirv/${src//\//.}.spv" "$src"
done

for spv in spirv/*.spv; do
    if [[ -e "$spv" && -z "${source_of[$spv]:-}" ]]; then
        rm -- "$spv"
        echo "removed stale shaders/$spv (no source produces it)"
    fi
done
