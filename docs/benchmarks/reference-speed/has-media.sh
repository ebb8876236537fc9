#!/bin/bash
# The reference's texel buffer HAS_MEDIA specialisation: samples/s before (kiln-play-prev) and after.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w20; mkdir -p $W
L=$OUT/log20.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
ref() { local bin=$1 name=$2 size=$3 spp=$4; echo "== reference $bin $name $size $spp" >> $L; /usr/bin/time -f "wall %e s, max RSS %M KB" -o $W/time.txt timeout 100 $B/$bin $W/$name.kiln --headless --reference --spp $spp --size $size -o $W/$name-$bin.exr 2>&1 | tail -1 | sed 's/.*spp) in//' >> $L; cat $W/time.txt >> $L; }
for r in 1 2; do
  for bin in kiln-play-prev kiln-play; do
    ref $bin toycar 640x360 1024
    ref $bin pica 800x450 1024
    ref $bin lamp 640x360 1024
  done
done
for n in toycar pica lamp; do echo "== diff $n prev new" >> $L; $B/kiln-bench --diff $W/$n-kiln-play-prev.exr $W/$n-kiln-play.exr 2>&1 | head -1 >> $L; done
echo done >> $L
