#!/bin/bash
# Clear coat on the GPU: ToyCar's reference (samples/s, image), its frames with the raster coat
# (kiln-play) and without (kiln-play-nocoat, commit 69119f2: same format), against the reference.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp helmet $S/DamagedHelmet.glb --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml
ref() { local name=$1 spp=$2 out=$3; echo "== reference $name $spp" >> $L; timeout 150 $B/kiln-play $W/$name.kiln --headless --reference --spp $spp --size 640x360 -o $out >> $L 2>&1; }
ref toycar 4096 $OUT/toycar_ref.exr
ref toycar 1024 $W/toycar_ref1024.exr
ref helmet 1024 $W/helmet_ref.exr
ref pica 1024 $W/pica_ref.exr
ref toycar 1024 $W/toycar_ref1024b.exr
echo "== noise floor (1024 vs 4096)" >> $L
$B/kiln-bench --diff $OUT/toycar_ref.exr $W/toycar_ref1024.exr >> $L 2>&1
for p in kiln-play kiln-play-nocoat; do
  for args in "--frames 1" "--frames 64" "--preset rt-4 --frames 16"; do
    tag=$(echo "$p $args" | tr ' -' '__')
    echo "== frame $p $args" >> $L
    timeout 60 $B/$p $W/toycar.kiln --headless --size 640x360 $args -o $W/$tag.exr >> $L 2>&1
    $B/kiln-bench --diff $OUT/toycar_ref.exr $W/$tag.exr >> $L 2>&1
    mkdir -p $OUT/$tag && cp kiln-bench-out/flip.png $OUT/$tag/ 2>/dev/null
  done
done
timeout 60 $B/kiln-play $W/toycar.kiln --headless --size 800x450 --frames 64 -o $OUT/toycar_default.png >> $L 2>&1
timeout 60 $B/kiln-play-nocoat $W/toycar.kiln --headless --size 800x450 --frames 64 -o $OUT/toycar_default_nocoat.png >> $L 2>&1
echo "== bench toycar default and rt-4" >> $L
timeout 60 $B/kiln-play $W/toycar.kiln --headless --bench --frames 200 --size 1600x900 >> $L 2>&1
timeout 60 $B/kiln-play-nocoat $W/toycar.kiln --headless --bench --frames 200 --size 1600x900 >> $L 2>&1
echo done >> $L
