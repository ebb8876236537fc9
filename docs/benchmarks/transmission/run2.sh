#!/bin/bash
# Where ToyCar's reference spends its time: variants of the file, one reference each, and the
# traversal's ray throughput against pica_pica's.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log2.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp slow $S/toycar/ToyCar.gltf --environment studio --bvh-preset slow
comp fast $S/toycar/ToyCar.gltf --environment studio --bvh-preset fast
comp noemit $S/toycar/ToyCar.gltf --environment studio -c /tmp/p/noemit.toml
comp noenv $S/toycar/ToyCar.gltf
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml
ref() { local name=$1; echo "== reference $name ${KILN_DIAG_BOUNCES:-all}" >> $L; timeout 100 $B/kiln-play-diag $W/$name.kiln --headless --reference --spp 1024 --size 640x360 -o $W/$name-${KILN_DIAG_BOUNCES:-all}.exr >> $L 2>&1; }
for r in 1 2; do
  for v in toycar slow fast noemit noenv pica; do ref $v; done
  for v in toycar noemit noenv pica; do KILN_DIAG_BOUNCES=1 ref $v; done
done
for v in toycar slow pica; do
  echo "== bench-rays $v" >> $L
  timeout 100 $B/kiln-play $W/$v.kiln --headless --bench-rays --size 1600x900 >> $L 2>&1
done
echo done >> $L
