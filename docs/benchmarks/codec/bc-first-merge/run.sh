#!/usr/bin/env bash
# Issue 18 on the GPU machine: file sizes of the defaults (BC textures, auto codec, line space
# within twice the geometry), --codec zstd, --texture-format rgba8; first frame cold and warm
# pipeline cache at 1600x900; BC textures sampled by every pass on NVIDIA (raster, visibility
# and the ray-traced passes' GLSL decode) against the rgba8 file.
set -uo pipefail
for f in .gl/*.deb; do dpkg -x "$f" / >/dev/null; done; ldconfig
B=.devrun/new
S=.devrun/scenes
mkdir -p $OUT/r
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $OUT/r/gpu.txt 2>&1
c() { local name=$1; shift; /usr/bin/time -f "$name wall %e s" $B/kiln compile "$@" -q -o /tmp/$name.kiln 2>> $OUT/r/log.txt; echo "$name $(stat -c %s /tmp/$name.kiln)" >> $OUT/r/sizes.txt; }
c pica_default $S/pica_pica/scene.gltf --config $S/pica_pica.toml
c pica_zstd $S/pica_pica/scene.gltf --config $S/pica_pica.toml --codec zstd
c pica_rgba8 $S/pica_pica/scene.gltf --config $S/pica_pica.toml --texture-format rgba8
c pica_rgba8_zstd $S/pica_pica/scene.gltf --config $S/pica_pica.toml --texture-format rgba8 --codec zstd
c cornell_default $S/cornell_box/scene.gltf --config $S/cornell_box.toml
c cornell_zstd $S/cornell_box/scene.gltf --config $S/cornell_box.toml --codec zstd
du -b $S/pica_pica $S/cornell_box >> $OUT/r/sizes.txt
$B/kiln inspect /tmp/pica_default.kiln > $OUT/r/inspect_default.txt 2>&1
$B/kiln inspect /tmp/pica_zstd.kiln > $OUT/r/inspect_zstd.txt 2>&1
# First frame: cold pipeline cache (none), then warm; per file.
for f in pica_default pica_zstd pica_rgba8; do
  rm -rf ~/.cache/kiln
  $B/kiln-play /tmp/$f.kiln --bench --json --size 1600x900 > $OUT/r/bench-$f-cold.json 2>> $OUT/r/log.txt
  $B/kiln-play /tmp/$f.kiln --bench --json --size 1600x900 > $OUT/r/bench-$f-warm.json 2>> $OUT/r/log.txt
done
for f in pica_default pica_rgba8; do
  for g in raster visibility; do
    $B/kiln-play /tmp/$f.kiln --headless --size 800x450 --gbuffer $g --reflections rt --ao rt --validate -o $OUT/r/$f-$g.exr 2>> $OUT/r/log.txt
  done
  $B/kiln-play /tmp/$f.kiln --reference --spp 64 --size 400x225 -o $OUT/r/$f-ref.exr 2>> $OUT/r/log.txt
done
$B/kiln-bench /tmp/pica_default.kiln --size 320x180 --reference-spp 64 --timing-frames 5 --warmup 1 --frames-accumulated 1 --effects frame --validate --out /tmp/val -q >> $OUT/r/log.txt 2>&1; echo "validated sweep exit $?" >> $OUT/r/log.txt
cd $OUT && tar czf files.tgz r && rm -rf r
