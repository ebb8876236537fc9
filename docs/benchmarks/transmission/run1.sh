#!/bin/bash
# Transmission on the GPU; where ToyCar's reference spends its time.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp toycar8 $S/toycar/ToyCar.gltf --environment studio --texture-format rgba8
comp helmet $S/DamagedHelmet.glb --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
cp $W/*.compile.txt $OUT/ 2>/dev/null
ref() { local bin=$1 name=$2 spp=$3 out=$4; echo "== reference $bin $name $spp ${KILN_DIAG_BOUNCES:-all}" >> $L; timeout 150 $B/$bin $W/$name.kiln --headless --reference --spp $spp --size 640x360 -o $out >> $L 2>&1; }
ref kiln-play toycar 4096 $OUT/toycar_ref.exr
ref kiln-play toycar 1024 $W/toycar_ref1024.exr
ref kiln-play toycar8 1024 $W/toycar8_ref1024.exr
ref kiln-play helmet 1024 $W/helmet_ref.exr
ref kiln-play pica 1024 $W/pica_ref.exr
ref kiln-play lamp 4096 $OUT/lamp_ref.exr
echo "== noise floor toycar (1024 vs 4096)" >> $L
$B/kiln-bench --diff $OUT/toycar_ref.exr $W/toycar_ref1024.exr >> $L 2>&1
for b in 1 2 3 5 8; do
  for s in toycar helmet pica; do
    KILN_DIAG_BOUNCES=$b ref kiln-play-diag $s 512 $W/diag_${s}_$b.exr
  done
done
for args in "--frames 1" "--frames 64" "--preset rt-4 --frames 16"; do
  for s in toycar lamp; do
    tag=$(echo "$s $args" | tr ' -' '__')
    echo "== frame $s $args" >> $L
    timeout 60 $B/kiln-play $W/$s.kiln --headless --size 640x360 $args -o $W/$tag.exr >> $L 2>&1
    $B/kiln-bench --diff $OUT/${s}_ref.exr $W/$tag.exr >> $L 2>&1
  done
done
timeout 60 $B/kiln-play $W/toycar.kiln --headless --size 800x450 --frames 64 -o $OUT/toycar_default.png >> $L 2>&1
timeout 60 $B/kiln-play $W/toycar.kiln --headless --size 800x450 --preset rt-4 --frames 64 -o $OUT/toycar_rt4.png >> $L 2>&1
timeout 60 $B/kiln-play $W/lamp.kiln --headless --size 800x450 --frames 64 -o $OUT/lamp_default.png >> $L 2>&1
timeout 60 $B/kiln-play $W/lamp.kiln --headless --size 800x450 --preset rt-4 --frames 64 -o $OUT/lamp_rt4.png >> $L 2>&1
echo "== bench toycar default" >> $L
timeout 60 $B/kiln-play $W/toycar.kiln --headless --bench --frames 200 --size 1600x900 >> $L 2>&1
echo done >> $L
