#!/bin/bash
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
cd /tmp
$B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_pica.toml --shaft-variants none -o pica.kiln -q >> $L 2>&1
$B/kiln compile $S/box/CornellBox-Original.obj -c $S/box/camera.toml --shaft-variants none -o box.kiln -q >> $L 2>&1
ls -la *.kiln >> $L
P="$B/kiln-play --headless --size 1600x900"
( time $P pica.kiln --reference --spp 4096 -o pica-ref.exr ) >> $L 2>&1
gzip -1 -c pica-ref.exr > $OUT/pica-ref.exr.gz
d() { echo "== $1: ${@:3}" >> $L; $P $2 "${@:3}" -o $1.exr >> $L 2>&1; $B/kiln-bench --diff $(echo $2 | sed 's/.kiln/-ref.exr/') $1.exr >> $L 2>&1; }
d probes1 pica.kiln --gbuffer visibility
d probes4 pica.kiln --gbuffer visibility --frames 4
d probes64 pica.kiln --gbuffer visibility --frames 64
d probes1raster pica.kiln
d pr-rtsh pica.kiln --gbuffer visibility --shadows rt
d pr-rtrefl pica.kiln --gbuffer visibility --reflections rt
d pr-rtboth pica.kiln --gbuffer visibility --shadows rt --reflections rt
d pr-rtboth4 pica.kiln --gbuffer visibility --shadows rt --reflections rt --frames 4
d pr-gtao pica.kiln --gbuffer visibility --ao gtao
d pr-refnone pica.kiln --gbuffer visibility --reflections none
d rt4-1 pica.kiln --gbuffer visibility --preset rt-4
d rt4-64 pica.kiln --gbuffer visibility --preset rt-4 --frames 64
d rt-1 pica.kiln --gbuffer visibility --preset rt --aa accumulate
d rt-4 pica.kiln --gbuffer visibility --preset rt --aa accumulate --frames 4
d rt-16 pica.kiln --gbuffer visibility --preset rt --aa accumulate --frames 16
gzip -1 -c rt-4.exr > $OUT/rt-4.exr.gz
( time $P box.kiln --reference --spp 4096 -o box-ref.exr ) >> $L 2>&1
gzip -1 -c box-ref.exr > $OUT/box-ref.exr.gz
d box1 box.kiln --gbuffer visibility
d box4 box.kiln --gbuffer visibility --frames 4
$P pica.kiln --gbuffer visibility --bench --frames 100 >> $L 2>&1
ls -la $OUT >> $L
