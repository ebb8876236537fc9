#!/bin/bash
# Issue 45, third call: where ToyCar's time goes (traversal rates; with and without the environment).
set -u
cd "$(dirname "$0")"; tar xzf pack.tgz
B=$PWD/bin; S=$PWD/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log.txt
$B/kiln compile $S/toycar/ToyCar.gltf --environment studio -o $W/toycar.kiln -q > /dev/null 2>&1
$B/kiln compile $S/toycar/ToyCar.gltf -o $W/toycar_noenv.kiln -q > /dev/null 2>&1
$B/kiln compile $S/lamp/LightsPunctualLamp.gltf --environment studio -o $W/lamp.kiln -q > /dev/null 2>&1
$B/kiln compile $S/rooms/room_unit.obj -o $W/room.kiln -q > /dev/null 2>&1
for f in toycar toycar_noenv lamp room; do
  echo "== bench-rays $f" >> $L
  timeout 100 $B/kiln-play $W/$f.kiln --headless --bench-rays --size 1600x900 --frames 20 >> $L 2>&1
  echo "== reference $f" >> $L
  timeout 100 $B/kiln-play $W/$f.kiln --headless --reference --spp 512 --size 640x360 -o $W/r.exr >> $L 2>&1
  timeout 100 $B/kiln-play $W/$f.kiln --headless --reference --spp 512 --size 640x360 -o $W/r.exr >> $L 2>&1
done
$B/kiln inspect $W/toycar.kiln | tail -25 >> $L
