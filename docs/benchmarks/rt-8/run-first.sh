#!/bin/bash
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
cd /tmp
$B/kiln compile $S/box/CornellBox-Original.obj -c $S/box/camera.toml -o box.kiln -q >> $L 2>&1
P="$B/kiln-play box.kiln --headless --size 1600x900"
( time $P --reference --spp 4096 -o ref.exr ) >> $L 2>&1
run() { # name frames args...
  n=$1; f=$2; shift 2
  $P --frames $f "$@" -o $n-$f.exr > /dev/null 2>> $OUT/err.txt
  echo "$n f$f $($B/kiln-bench --diff ref.exr $n-$f.exr 2>&1 | tr '\n' ' ')" >> $L
}
for f in 1 4 64; do
  run rt4 $f --preset rt-4
  run rt8 $f --preset rt-4 --gi-bounces 8
done
run rt4-nodenoise 64 --preset rt-4 --denoise none
run rt8-nodenoise 64 --preset rt-4 --gi-bounces 8 --denoise none
run probes 64 --preset probes
$P --bench --json --preset rt-4 > $OUT/bench-rt4.json 2>>$OUT/err.txt
$P --bench --json --preset rt-4 --gi-bounces 8 > $OUT/bench-rt8.json 2>>$OUT/err.txt
echo done >> $L
