#!/bin/bash
# One shadow ray per path vertex (environment or emitter, chosen by power) against two:
# reference samples/s and error at equal samples, previous (kiln-play-prev) and new binary.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w5; mkdir -p $W
L=$OUT/log5.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/glTF/ToyCar.gltf --environment studio
comp lamp $S/lamp/glTF/LightsPunctualLamp.gltf --environment studio
comp helmet $S/helmet/glTF-Binary/DamagedHelmet.glb --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
ref() { local bin=$1 name=$2 spp=$3 tag=$4; echo "== reference $bin $name $spp $tag" >> $L; timeout 100 $B/$bin $W/$name.kiln --headless --reference --spp $spp --size 640x360 -o $W/$name-$tag.exr 2>&1 | tail -1 | sed 's/.*spp) in//' >> $L; }
for n in toycar lamp helmet pica; do ref kiln-play $n 8192 ref; done
date >> $L
for r in 1 2 3; do for n in toycar lamp helmet pica; do
  ref kiln-play-prev $n 1024 prev-speed$r
  ref kiln-play $n 1024 new-speed$r
done; done
date >> $L
for n in toycar lamp helmet pica; do
  for spp in 64 256; do
    ref kiln-play-prev $n $spp prev$spp
    ref kiln-play $n $spp new$spp
    echo "== $n $spp spp against the new 8192: prev, new" >> $L
    $B/kiln-bench --diff $W/$n-ref.exr $W/$n-prev$spp.exr 2>&1 | head -1 >> $L
    $B/kiln-bench --diff $W/$n-ref.exr $W/$n-new$spp.exr 2>&1 | head -1 >> $L
  done
done
echo done >> $L
