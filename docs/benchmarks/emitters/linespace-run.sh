#!/bin/bash
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
cd /tmp
( time $B/kiln compile $S/box/CornellBox-Original.obj -c $S/box/camera.toml -o boxls.kiln -q ) >> $L 2>&1
ls -la boxls.kiln >> $L
P="$B/kiln-play --headless --size 1600x900 --gbuffer visibility"
$P boxls.kiln --reference --spp 4096 -o box-ref.exr >> $L 2>&1
d() { echo "== $1: ${@:2}" >> $L; $P boxls.kiln "${@:2}" -o $1.exr >> $L 2>&1; $B/kiln-bench --diff box-ref.exr $1.exr >> $L 2>&1; }
for f in 1 4; do
d rt$f --shadows rt --frames $f
d lsends$f --shadows linespace --frames $f
d lsfilled$f --shadows linespace --ls-shadow-test filled --frames $f
d lsnone$f --shadows linespace --direct none --frames $f
done
for s in "--shadows rt" "--shadows linespace" "--shadows linespace --ls-shadow-test filled"; do
echo "== bench $s" >> $L
timeout 60 $B/kiln-play boxls.kiln --headless --bench --frames 200 --size 1600x900 --gbuffer visibility $s >> $L 2>&1
done
echo "== kiln-bench direct chart" >> $L
timeout 200 $B/kiln-bench boxls.kiln --effects direct,shadows --frames-accumulated 1,4 --size 1600x900 --reference-spp 4096 -q -o /tmp/bd >> $L 2>&1
