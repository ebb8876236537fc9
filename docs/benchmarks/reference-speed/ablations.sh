#!/bin/bash
# Ablations of the reference path tracer's cost per sample (ToyCar, pica).
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w16; mkdir -p $W
L=$OUT/log16.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp toycarslow $S/toycar/ToyCar.gltf --environment studio --bvh-preset slow
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
ref() { local bin=$1 name=$2 size=$3 spp=$4; echo "== reference $bin $name $size $spp" >> $L; timeout 100 $B/$bin $W/$name.kiln --headless --reference --spp $spp --size $size -o $W/$name-$bin.exr 2>&1 | tail -1 | sed 's/.*spp) in//' >> $L; }
for r in 1 2; do
  for bin in kiln-play kiln-play-noenv kiln-play-nonee kiln-play-noshadow kiln-play-notex; do
    ref $bin toycar 640x360 1024
    ref $bin pica 800x450 1024
  done
  ref kiln-play toycarslow 640x360 1024
done
echo done >> $L
