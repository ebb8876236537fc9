#!/bin/bash
# 1,024 probe paths for glossy scenes (the binary of run12 had the rule switched off): pica, ToyCar.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w13; mkdir -p $W
L=$OUT/log13.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; local t0=$(date +%s%N); $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$? $(( ($(date +%s%N) - t0) / 1000000 )) ms" >> $L; }
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
comp pica256 $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none --probe-rays 256
comp toycar $S/toycar/ToyCar.gltf --environment studio
$B/kiln plan $S/pica_pica/scene.gltf -c $S/pica_pica.toml 2>&1 | grep " probes " >> $L
$B/kiln plan $S/toycar/ToyCar.gltf --environment studio 2>&1 | grep " probes " >> $L
ref() { local name=$1 size=$2; echo "== reference $name $size" >> $L; timeout 150 $B/kiln-play $W/$name.kiln --headless --reference --spp 4096 --size $size -o $W/$name-ref.exr 2>&1 | tail -1 >> $L; }
ref pica 1600x900; ref toycar 640x360
frame() { local ref=$1 file=$2 size=$3 tag=$4; shift 4; echo "== frame $file $tag $*" >> $L; timeout 120 $B/kiln-play $W/$file.kiln --headless --size $size "$@" -o $W/f.exr > $W/play.txt 2>&1 || tail -3 $W/play.txt >> $L; $B/kiln-bench --diff $W/$ref-ref.exr $W/f.exr 2>&1 | head -1 >> $L; }
for f in pica pica256; do
  frame pica $f 1600x900 default
  for p in probes probes-rt; do frame pica $f 1600x900 $p --gbuffer visibility --preset $p; frame pica $f 1600x900 $p-4 --gbuffer visibility --preset $p --frames 4; done
done
frame toycar toycar 640x360 default
frame toycar toycar 640x360 rt4-16 --preset rt-4 --frames 16
echo done >> $L
