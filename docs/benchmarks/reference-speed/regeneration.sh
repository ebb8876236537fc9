#!/bin/bash
# Path regeneration in the reference: samples/s before (kiln-play-prev) and after, per dispatch K.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w15; mkdir -p $W
L=$OUT/log15.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; local t0=$(date +%s%N); $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$? $(( ($(date +%s%N) - t0) / 1000000 )) ms" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
comp box $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml --shaft-variants none
ref() { local bin=$1 name=$2 size=$3 spp=$4; echo "== reference $bin $name $size $spp" >> $L; timeout 100 $B/$bin $W/$name.kiln --headless --reference --spp $spp --size $size -o $W/$name-$bin.exr 2>&1 | tail -1 >> $L; }
for r in 1 2; do
  for bin in kiln-play-prev kiln-play kiln-play-k4 kiln-play-k64; do
    ref $bin toycar 640x360 1024
    ref $bin pica 800x450 1024
    ref $bin lamp 640x360 1024
    ref $bin box 640x360 1024
  done
done
for n in toycar pica lamp box; do echo "== diff $n prev new" >> $L; $B/kiln-bench --diff $W/$n-kiln-play-prev.exr $W/$n-kiln-play.exr 2>&1 | head -1 >> $L; done
echo done >> $L
