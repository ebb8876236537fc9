#!/bin/bash
# DamagedHelmet under the studio environment at 1600x900: the default frame against the reference
# (issue 44's target: FLIP 0.08).
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
$B/kiln compile $S/DamagedHelmet.glb --environment studio -o $W/helmet.kiln -q >> $L 2>&1; echo "compile rc=$?" >> $L
echo "== reference 4096" >> $L
timeout 120 $B/kiln-play $W/helmet.kiln --headless --reference --spp 4096 --size 1600x900 -o $W/ref.exr >> $L 2>&1
timeout 120 $B/kiln-play $W/helmet.kiln --headless --reference --spp 1024 --size 1600x900 -o $W/ref1024.exr >> $L 2>&1
echo "== noise floor" >> $L; $B/kiln-bench --diff $W/ref.exr $W/ref1024.exr >> $L 2>&1
for args in "--frames 1" "--frames 64" "--preset rt-4 --frames 16"; do
  tag=$(echo "$args" | tr ' -' '__')
  echo "== frame $args" >> $L
  timeout 60 $B/kiln-play $W/helmet.kiln --headless --size 1600x900 $args -o $W/$tag.exr >> $L 2>&1
  $B/kiln-bench --diff $W/ref.exr $W/$tag.exr >> $L 2>&1
done
timeout 60 $B/kiln-play $W/helmet.kiln --headless --size 800x450 --frames 64 -o $OUT/helmet_default.png >> $L 2>&1
echo "== bench default" >> $L
timeout 60 $B/kiln-play $W/helmet.kiln --headless --bench --frames 200 --size 1600x900 >> $L 2>&1
echo done >> $L
