#!/bin/bash
# Stochastic texture filtering in the reference path tracer: samples/s and error at equal samples.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w14; mkdir -p $W
L=$OUT/log14.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
ref() { local bin=$1 name=$2 size=$3 spp=$4 tag=$5; echo "== reference $bin $name $size $spp" >> $L; timeout 200 $B/$bin $W/$name.kiln --headless --reference --spp $spp --size $size -o $W/$name-$tag.exr 2>&1 | tail -1 >> $L; }
ref kiln-play toycar 640x360 16384 big
for r in 1 2; do for bin in kiln-play kiln-play-prev; do ref $bin toycar 640x360 1024 $bin; done; done
for bin in kiln-play kiln-play-prev; do echo "== diff $bin toycar" >> $L; $B/kiln-bench --diff $W/toycar-big.exr $W/toycar-$bin.exr 2>&1 | head -1 >> $L; done
ref kiln-play pica 800x450 4096 big
for r in 1 2; do for bin in kiln-play kiln-play-prev; do ref $bin pica 800x450 256 $bin; done; done
for bin in kiln-play kiln-play-prev; do echo "== diff $bin pica" >> $L; $B/kiln-bench --diff $W/pica-big.exr $W/pica-$bin.exr 2>&1 | head -1 >> $L; done
for r in 1 2; do for bin in kiln-play kiln-play-prev; do ref $bin lamp 640x360 1024 $bin; done; done
echo done >> $L
