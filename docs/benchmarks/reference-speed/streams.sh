#!/bin/bash
# Samples of a pixel side by side in the path tracer's workgroup (KILN_PT_STREAMS 1, 2, 4):
# reference samples/s at 640x360 and 1600x900; the images of 1 and 2 compared.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w8; mkdir -p $W
L=$OUT/log8.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/glTF/ToyCar.gltf --environment studio
comp lamp $S/lamp/glTF/LightsPunctualLamp.gltf --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
for r in 1 2; do for sz in 640x360 1600x900; do for n in toycar lamp pica; do for k in 1 2 4; do
  echo "== r$r $n $sz streams $k" >> $L
  KILN_PT_STREAMS=$k timeout 100 $B/kiln-play-streams $W/$n.kiln --reference --spp 1024 --size $sz -o $W/$n-$sz-$k.exr 2>&1 | tail -1 | sed 's/.*spp) in//' >> $L
done; done; done; done
for n in toycar lamp pica; do echo "== $n 640x360 streams 1 vs 2, 1 vs 4" >> $L; $B/kiln-bench --diff $W/$n-640x360-1.exr $W/$n-640x360-2.exr -o $W/d 2>&1 | head -1 >> $L; $B/kiln-bench --diff $W/$n-640x360-1.exr $W/$n-640x360-4.exr -o $W/d 2>&1 | head -1 >> $L; done
echo done >> $L
