#!/bin/bash
# Session call 4: the metal bounce with its second hits' shadow rays deferred: pica_pica's frame
# chart (every preset, 1 and 16 frames), the reflection pass's time with and without, and the
# denser probe spacings with the final binary.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w4; mkdir -p $W/x
L=$OUT/log4.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; local t0=$(date +%s%N); timeout 200 $B/kiln compile $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none "$@" -o $W/$name.kiln > $W/c-$name.txt 2>&1; local rc=$?; local t1=$(date +%s%N); echo "compile $name $* rc=$rc $(( (t1 - t0) / 1000000 )) ms, $(stat -c %s $W/$name.kiln) bytes" >> $L; grep -i "probes " $W/c-$name.txt | head -2 >> $L; }
comp pica
date >> $L
timeout 300 $B/kiln-bench $W/pica.kiln --size 1600x900 --effects frame --frames-accumulated 1,16 --reference-spp 4096 -o $W/bench -q >> $L 2>&1; echo "bench rc=$?" >> $L
cp $W/bench/results.json $OUT/pica-results.json
cp $W/bench/frame.png $OUT/pica-frame.png 2>/dev/null
date >> $L
SZ=1600x900
bench() { local f=$1; shift; echo "== bench $f: $*" >> $L; timeout 60 $B/kiln-play $W/$f.kiln --headless --size $SZ --bench --frames 200 "$@" 2>&1 | grep -v "^note" | grep -i -E "^(reflections|total)" >> $L; }
for r in 1 2; do
  bench pica --preset probes-rt-refl --reflection-metal-bounce 0
  bench pica --preset probes-rt-refl
done
timeout 60 $B/kiln-play $W/pica.kiln --reference --spp 4096 --size $SZ -o $W/x/ref4k.exr 2>&1 | tail -1 >> $L
run() { local f=$1; local name=$2; shift; shift; echo "== $name: $f $*" >> $L; timeout 60 $B/kiln-play $W/$f.kiln --headless --size $SZ --preset probes-rt-refl "$@" -o $W/x/$name.exr > /dev/null 2>>$W/err.txt || echo FAILED >> $L; $B/kiln-bench --diff $W/x/ref4k.exr $W/x/$name.exr -o $W/d 2>&1 | head -1 >> $L; }
run pica d16 --frames 16
run pica d16mb0 --frames 16 --reflection-metal-bounce 0
for sp in 0.8 0.6; do
  comp s$sp --probe-spacing $sp
  run s$sp s${sp}_16 --frames 16
  run s$sp s${sp}_1 --frames 1
  bench s$sp --preset probes-rt-refl
done
date >> $L
echo done >> $L
