#!/bin/bash
# Diagnosis: how much of pica_pica's converged frame error is the missing pixel filter (aliasing)?
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w1; mkdir -p $W/img
L=$OUT/log1.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
date >> $L
$B/kiln compile $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none -o $W/pica.kiln -q > $W/compile.txt 2>&1; echo "compile rc=$?" >> $L; tail -3 $W/compile.txt >> $L
date >> $L
SZ=1600x900
timeout 200 $B/kiln-play $W/pica.kiln --reference --spp 4096 --size $SZ -o $W/ref.exr >> $L 2>&1; echo "ref rc=$?" >> $L
timeout 200 $B/kiln-play-center $W/pica.kiln --reference --spp 4096 --size $SZ -o $W/center.exr >> $L 2>&1; echo "center rc=$?" >> $L
date >> $L
d() { echo "== $1 vs $2" >> $L; $B/kiln-bench --diff $W/$1.exr $W/$2.exr -o $W/d_$1_$2 >> $L 2>&1; cp $W/d_$1_$2/flip.png $W/img/$1_$2.png 2>/dev/null; }
d ref center
run() { local name=$1; shift; echo "== render $name: $*" >> $L; timeout 120 $B/kiln-play $W/pica.kiln --headless --size $SZ "$@" -o $W/$name.exr >> $L 2>&1 || echo "FAILED $name" >> $L; d ref $name; d center $name; }
run rt8_64 --preset rt-8 --frames 64
run rt8_64_taa --preset rt-8 --frames 64 --aa taa --taa-weights linear --taa-frames 1024
run rt_64 --preset rt --frames 64
run prt_16 --preset probes-rt --frames 16
run prt_64 --preset probes-rt --frames 64
run prt_16_taa --preset probes-rt --frames 16 --aa taa --taa-weights linear --taa-frames 1024
run prt_64_taa --preset probes-rt --frames 64 --aa taa --taa-weights linear --taa-frames 1024
run prt_64_acc --preset probes-rt --frames 64 --aa accumulate
date >> $L
tar czf $OUT/flips.tgz -C $W img
cd $W && python3 -c "print('py ok')" >> $L 2>&1
echo done >> $L
