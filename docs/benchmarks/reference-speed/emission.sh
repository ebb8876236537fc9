#!/bin/bash
# Stochastic emission in NEE + EMLU sub-triangle centroids: ToyCar/lamp reference speed and noise, prev vs new.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w17; mkdir -p $W
L=$OUT/log17.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local k=$1 name=$2; shift 2; $B/$k compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $k $name rc=$?" >> $L; }
comp kiln toycar $S/toycar/ToyCar.gltf --environment studio
comp kiln-prev toycar-prev $S/toycar/ToyCar.gltf --environment studio
comp kiln lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
comp kiln-prev lamp-prev $S/lamp/LightsPunctualLamp.gltf --environment studio
ref() { local bin=$1 name=$2 spp=$3 tag=$4; shift 4; echo "== reference $bin $name $spp $tag" >> $L; timeout 100 $B/$bin $W/$name.kiln --headless --reference --spp $spp --size 640x360 "$@" -o $W/$name-$tag.exr 2>&1 | tail -1 | sed 's/.*spp) in//' >> $L; }
ref kiln-play toycar 4096 ref
ref kiln-play lamp 4096 ref
for r in 1 2; do
  ref kiln-play-prev toycar-prev 256 prev$r
  ref kiln-play toycar 256 new$r
  ref kiln-play-prev lamp-prev 256 prev$r
  ref kiln-play lamp 256 new$r
done
for n in toycar lamp; do
  echo "== $n 256 spp against the new 4096: prev, new" >> $L
  $B/kiln-bench --diff $W/$n-ref.exr $W/$n-prev-prev1.exr 2>&1 | head -1 >> $L
  $B/kiln-bench --diff $W/$n-ref.exr $W/$n-new1.exr 2>&1 | head -1 >> $L
done
frame() { local name=$1 ref=$2 tag=$3; shift 3; echo "== frame $name $tag $*" >> $L; timeout 100 $B/kiln-play $W/$name.kiln --headless --size 640x360 "$@" -o $W/$name-f-$tag.exr > /dev/null 2>&1; $B/kiln-bench --diff $W/$ref-ref.exr $W/$name-f-$tag.exr 2>&1 | head -1 >> $L; }
for n in toycar lamp; do
  frame $n-prev $n default; frame $n $n default
  frame $n-prev $n rt4-16 --preset rt-4 --frames 16; frame $n $n rt4-16 --preset rt-4 --frames 16
done
echo done >> $L
