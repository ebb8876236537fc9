#!/bin/bash
# What remains of pica_pica's error after the reflections' probes: EXRs at 800x450.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w7; mkdir -p $W/x
L=$OUT/log7.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
$B/kiln compile $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none -o $W/pica.kiln -q > $W/c.txt 2>&1; echo "compile rc=$?" >> $L
SZ=800x450
timeout 100 $B/kiln-play $W/pica.kiln --reference --spp 8192 --size $SZ -o $W/x/ref.exr 2>&1 | tail -1 >> $L
run() { local name=$1; shift; echo "== $name: $*" >> $L; timeout 60 $B/kiln-play $W/pica.kiln --headless --size $SZ "$@" -o $W/x/$name.exr > /dev/null 2>>$W/err.txt || echo FAILED >> $L; $B/kiln-bench --diff $W/x/ref.exr $W/x/$name.exr -o $W/d 2>&1 | head -1 >> $L; }
run prr16 --preset probes-rt-refl --frames 16
run prr16full --preset probes-rt-refl --reflection-res full --frames 16
run rt8 --preset rt-8 --frames 64
run prr16_noaa --preset probes-rt-refl --frames 16 --aa accumulate
for f in ref prr16 rt8; do gzip -c $W/x/$f.exr > $OUT/$f.exr.gz; done
echo done >> $L
