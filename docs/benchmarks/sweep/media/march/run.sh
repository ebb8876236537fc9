#!/usr/bin/env bash
# --media march on the GPU machine: per-pass GPU ms at 800x600 and 1920x1080 for 8..64 steps on
# pica_pica with a haze (3 lights) and the foggy Cornell box, and kiln-bench's media chart
# (time against error, against the media-enabled reference) on both.
set -uo pipefail
for f in .gl/*.deb; do dpkg -x "$f" / >/dev/null; done; ldconfig
B=.devrun/new
S=.devrun/scenes
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $OUT/gpu.txt 2>&1
( time $B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_fog.toml --shaft-variants none -q -o /tmp/pica_fog.kiln ) 2>> $OUT/log.txt
( time $B/kiln compile $S/cornell_box/scene.gltf --config $S/cornell_fog.toml --shaft-variants none -q -o /tmp/cornell_fog.kiln ) 2>> $OUT/log.txt
for scene in pica_fog cornell_fog; do
  for size in 800x600 1920x1080; do
    $B/kiln-play /tmp/$scene.kiln --bench --json --size $size > $OUT/bench-$scene-$size-none.json 2>> $OUT/log.txt
    for steps in 8 16 32 64; do
      $B/kiln-play /tmp/$scene.kiln --bench --json --size $size --media march --media-steps $steps > $OUT/bench-$scene-$size-$steps.json 2>> $OUT/log.txt
    done
  done
done
$B/kiln-play /tmp/pica_fog.kiln --headless --size 1600x900 --media march -o $OUT/pica_fog_march.png 2>> $OUT/log.txt
$B/kiln-play /tmp/cornell_fog.kiln --headless --size 800x600 --media march -o $OUT/cornell_fog_march.png 2>> $OUT/log.txt
echo "== sweeps" >> $OUT/log.txt
/usr/bin/time -f "wall %e s" $B/kiln-bench /tmp/cornell_fog.kiln --effects media --size 800x600 --reference-spp 4096 --out /tmp/out-cornell -q >> $OUT/log.txt 2>&1
/usr/bin/time -f "wall %e s" $B/kiln-bench /tmp/pica_fog.kiln --effects media --size 1600x900 --reference-spp 1024 --out /tmp/out-pica -q >> $OUT/log.txt 2>&1
for n in cornell pica; do mkdir -p $OUT/sweep-$n; (cd /tmp/out-$n && cp results.json results.csv index.html *.svg *.png $OUT/sweep-$n/ 2>/dev/null); done
cd $OUT && tar czf /tmp/media.tgz . && find $OUT -mindepth 1 -delete && mv /tmp/media.tgz $OUT/
