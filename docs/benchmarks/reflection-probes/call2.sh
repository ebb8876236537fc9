#!/bin/bash
# Diagnosis 2: where pica_pica's converged rt-8 frame differs from the reference (EXRs at 800x450).
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w2; mkdir -p $W/x
L=$OUT/log2.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
python3 -c "import numpy; print('numpy', numpy.__version__)" >> $L 2>&1
$B/kiln compile $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none -o $W/pica.kiln -q > $W/compile.txt 2>&1; echo "compile rc=$?" >> $L
SZ=800x450
timeout 100 $B/kiln-play $W/pica.kiln --reference --spp 8192 --size $SZ -o $W/x/ref.exr >> $L 2>&1; echo "ref rc=$?" >> $L
run() { local name=$1; shift; echo "== render $name: $*" >> $L; timeout 60 $B/kiln-play $W/pica.kiln --headless --size $SZ "$@" -o $W/x/$name.exr >> $W/play.txt 2>&1 || echo "FAILED $name" >> $L; $B/kiln-bench --diff $W/x/ref.exr $W/x/$name.exr -o $W/d >> $L 2>&1; }
run rt8 --preset rt-8 --frames 64
run rt8_reg0 --preset rt-8 --frames 64 --gi-regularize 0
run rt8_norefl --preset rt-8 --frames 64 --reflections none
run rt8_nodn --preset rt-8 --frames 64 --denoise none
run prt16 --preset probes-rt --frames 16
run rt8_nodirect --preset rt-8 --frames 64 --direct none
ls -la $W/x >> $L
for f in $W/x/*.exr; do gzip -c $f > $OUT/$(basename $f).gz; done
echo done >> $L
