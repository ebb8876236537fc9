#!/bin/bash
# Session call 5: pica_pica with probes 0.7 apart: its bake, file and first frame, and its frame
# chart (every preset, 1 and 16 frames) at 1600x900.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w5; mkdir -p $W/x
L=$OUT/log5.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; local t0=$(date +%s%N); timeout 300 $B/kiln compile $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none "$@" -o $W/$name.kiln > $W/c-$name.txt 2>&1; local rc=$?; local t1=$(date +%s%N); echo "compile $name $* rc=$rc $(( (t1 - t0) / 1000000 )) ms, $(stat -c %s $W/$name.kiln) bytes" >> $L; grep -i "probes " $W/c-$name.txt | head -2 >> $L; }
comp s0.7 --probe-spacing 0.7
date >> $L
timeout 300 $B/kiln-bench $W/s0.7.kiln --size 1600x900 --effects frame --frames-accumulated 1,16 --reference-spp 4096 --techniques frame:probes-rt-refl,frame:probes-rt,frame:probes -o $W/bench -q >> $L 2>&1; echo "bench rc=$?" >> $L
cp $W/bench/results.json $OUT/pica-s0.7-results.json
date >> $L
timeout 60 $B/kiln-play $W/s0.7.kiln --headless --size 1600x900 --bench --frames 200 --preset probes-rt-refl 2>&1 | grep -v "^note" | grep -i -E "^(reflections|probes|total)|first frame" >> $L
echo done >> $L
