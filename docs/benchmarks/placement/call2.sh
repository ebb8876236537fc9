#!/bin/bash
# Issue 45 on the GPU, second call: ToyCar and the lamp with transmission read as coverage.
set -u
cd "$(dirname "$0")"; tar xzf pack.tgz
B=$PWD/bin; S=$PWD/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; grep -i transmission $W/$name.compile.txt | head -2 >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp toycar100 $S/toycar/ToyCar100.gltf --environment studio
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
comp room_unit $S/rooms/room_unit.obj
for f in toycar toycar100 lamp room_unit toycar room_unit; do
  echo "== reference $f" >> $L
  timeout 120 $B/kiln-play $W/$f.kiln --headless --reference --spp 1024 --size 640x360 -o $W/ref_$f.exr >> $L 2>&1
done
bench() { local name=$1; shift; echo "== bench $name $*" >> $L; timeout 120 $B/kiln-play "$@" --headless --bench --frames 200 --size 1600x900 >> $L 2>&1; }
for f in toycar toycar100 lamp; do
  bench $f $W/$f.kiln --gbuffer visibility --shadows rt --reflections rt --gi rt
done
timeout 60 $B/kiln-play $W/toycar.kiln --headless --size 800x450 --preset rt-4 --frames 16 -o $OUT/toycar_rt4.png >> $L 2>&1
timeout 60 $B/kiln-play $W/lamp.kiln --headless --size 800x450 --preset rt-4 --frames 16 -o $OUT/lamp_rt4.png >> $L 2>&1
cp $W/ref_toycar.exr $W/ref_lamp.exr $OUT/
