#!/bin/bash
# pica_pica's frame chart (every preset, both G-buffers, 1 and 16 frames) after the reflections'
# hits were lit by the probes and the probes-rt-refl preset was added; H200, 1600x900.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w4; mkdir -p $W
L=$OUT/log4.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
$B/kiln compile $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none -o $W/pica.kiln -q > $W/c1.txt 2>&1; echo "compile pica rc=$?" >> $L
date >> $L
timeout 480 $B/kiln-bench $W/pica.kiln --size 1600x900 --effects frame --frames-accumulated 1,16 --reference-spp 4096 -o $W/bench -q >> $L 2>&1; echo "bench rc=$?" >> $L
date >> $L
cp $W/bench/results.json $OUT/pica-results.json
cp $W/bench/frame.png $OUT/pica-frame.png 2>/dev/null
echo done >> $L
