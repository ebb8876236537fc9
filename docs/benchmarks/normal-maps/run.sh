#!/bin/bash
# Normal maps: the frame's cotangent frame oriented (kiln-play-new) against HEAD (kiln-play).
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log3.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln-new compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp helmet $S/DamagedHelmet.glb --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
for s in toycar helmet pica lamp; do
  echo "== reference $s" >> $L
  timeout 100 $B/kiln-play $W/$s.kiln --headless --reference --spp 4096 --size 640x360 -o $W/$s-ref.exr >> $L 2>&1
  for p in kiln-play kiln-play-new; do
    for args in "--frames 1" "--frames 4" "--preset rt-4 --frames 16"; do
      tag=$s-$p-$(echo "$args" | tr -d ' -')
      echo "== frame $s $p $args" >> $L
      timeout 60 $B/$p $W/$s.kiln --headless --size 640x360 $args -o $W/$tag.exr > $W/play.txt 2>&1 || cat $W/play.txt >> $L
      $B/kiln-bench --diff $W/$s-ref.exr $W/$tag.exr >> $L 2>&1
    done
  done
done
cp $W/toycar-ref.exr $W/toycar-kiln-play-new-frames1.exr $OUT/
echo "== bench pica" >> $L
for p in kiln-play kiln-play-new; do timeout 60 $B/$p $W/pica.kiln --headless --size 1600x900 --bench --frames 100 2>&1 | grep -E "gbuffer|total" >> $L; done
echo done >> $L
