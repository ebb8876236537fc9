#!/bin/bash
# Light through thin-walled surfaces in the raster frame: kiln-play-t (this change) against kiln-play-new (f12a29a).
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log4.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln-new compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
comp box $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml --shaft-variants none
for s in lamp toycar pica box; do
  echo "== reference $s" >> $L
  timeout 100 $B/kiln-play-new $W/$s.kiln --headless --reference --spp 4096 --size 640x360 -o $W/$s-ref.exr >> $L 2>&1
  for p in kiln-play-new kiln-play-t; do
    for args in "--frames 1" "--preset hybrid --frames 4" "--preset rt-4 --frames 16"; do
      tag=$s-$p-$(echo "$args" | tr -d ' -')
      echo "== frame $s $p $args" >> $L
      timeout 60 $B/$p $W/$s.kiln --headless --size 640x360 $args -o $W/$tag.exr > $W/play.txt 2>&1 || cat $W/play.txt >> $L
      $B/kiln-bench --diff $W/$s-ref.exr $W/$tag.exr >> $L 2>&1
    done
  done
done
cp $W/lamp-ref.exr $W/lamp-kiln-play-new-frames1.exr $W/lamp-kiln-play-t-frames1.exr $OUT/
for p in kiln-play-new kiln-play-t; do echo "== bench pica $p" >> $L; timeout 60 $B/$p $W/pica.kiln --headless --size 1600x900 --bench --frames 100 2>&1 | grep -E "gbuffer|direct|total" >> $L; done
echo done >> $L
