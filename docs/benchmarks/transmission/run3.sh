#!/bin/bash
# One shadow ray per vertex where a scene has emitters and an environment: the reference's speed
# before (kiln-play-before, commit 80765a6) and after, in one call.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log3.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp helmet $S/DamagedHelmet.glb --environment studio
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml
for r in 1 2; do
  for v in toycar helmet lamp pica; do
    for bin in kiln-play-before kiln-play; do
      echo "== $r $bin $v" >> $L
      timeout 100 $B/$bin $W/$v.kiln --headless --reference --spp 1024 --size 640x360 -o $W/$v-$bin.exr >> $L 2>&1
    done
  done
done
ref() { timeout 150 $B/kiln-play-before $W/$1.kiln --headless --reference --spp 8192 --size 640x360 -o $W/$1-ref.exr >> $L 2>&1; }
for v in toycar helmet; do
  ref $v
  for bin in kiln-play-before kiln-play; do
    echo "== flip 1024 spp $bin $v against 8192 (before)" >> $L
    $B/kiln-bench --diff $W/$v-ref.exr $W/$v-$bin.exr >> $L 2>&1
  done
done
echo done >> $L
