#!/bin/bash
# Probes: double-sided backs by winding (kiln-new) against HEAD (kiln): default frames vs references.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log2.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local k=$1 name=$2; shift 2; $B/$k compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $k $name rc=$?" >> $L; $B/kiln inspect $W/$name.kiln 2>&1 | grep "irradiance probes" >> $L; }
for k in kiln kiln-new; do
  comp $k toycar-$k $S/toycar/ToyCar.gltf --environment studio
  comp $k pica-$k $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
  comp $k box-$k $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml --shaft-variants none
  comp $k helmet-$k $S/DamagedHelmet.glb --environment studio
done
ref() { local name=$1 size=$2; echo "== reference $name $size" >> $L; timeout 150 $B/kiln-play $W/$name-kiln.kiln --headless --reference --spp 4096 --size $size -o $W/$name-ref.exr >> $L 2>&1; }
ref toycar 640x360; ref helmet 640x360; ref box 1600x900; ref pica 1600x900
for s in "toycar 640x360" "helmet 640x360" "box 1600x900" "pica 1600x900"; do
  set -- $s
  for k in kiln kiln-new; do
    for f in 1 4; do
      echo "== frame $1 $k $f" >> $L
      timeout 60 $B/kiln-play $W/$1-$k.kiln --headless --size $2 --frames $f -o $W/$1-$k-$f.exr > $W/play.txt 2>&1 || cat $W/play.txt >> $L
      $B/kiln-bench --diff $W/$1-ref.exr $W/$1-$k-$f.exr >> $L 2>&1
    done
  done
done
cp $W/toycar-ref.exr $W/toycar-kiln-new-1.exr $W/toycar-kiln-1.exr $OUT/
timeout 60 $B/kiln-play $W/toycar-kiln-new.kiln --headless --size 1600x900 --bench --frames 100 | tail -30 >> $L 2>&1
echo done >> $L
