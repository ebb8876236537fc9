#!/bin/bash
# After the probes' sky fallback: pica (default and denser bakes), box, ToyCar, lamp; probes / probes-rt timing.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w8; mkdir -p $W
L=$OUT/log8.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; local t0=$(date +%s%N); $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$? $(( ($(date +%s%N) - t0) / 1000000 )) ms $(stat -c %s $W/$name.kiln) B" >> $L; }
PICA="$S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none"
comp pica $PICA
comp pica3 $PICA --probe-spacing 3 --probe-budget 64 --probe-rays 1024
comp picad $PICA --probe-spacing 2.5 --probe-budget 64 --probe-rays 1024
comp box $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml --shaft-variants none
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
ref() { local name=$1 size=$2; echo "== reference $name $size" >> $L; timeout 150 $B/kiln-play $W/$name.kiln --headless --reference --spp 4096 --size $size -o $W/$name-ref.exr 2>&1 | tail -1 >> $L; }
ref pica 1600x900; ref box 1600x900; ref toycar 640x360; ref lamp 640x360
frame() { local ref=$1 file=$2 size=$3 tag=$4; shift 4; echo "== frame $file $tag $*" >> $L; timeout 120 $B/kiln-play $W/$file.kiln --headless --size $size "$@" -o $W/f.exr > $W/play.txt 2>&1 || tail -3 $W/play.txt >> $L; $B/kiln-bench --diff $W/$ref-ref.exr $W/f.exr 2>&1 | head -1 >> $L; }
for f in pica pica3 picad; do for p in probes probes-rt; do for n in 1 4; do frame pica $f 1600x900 $p-$n --gbuffer visibility --preset $p --frames $n; done; done; done
frame pica pica 1600x900 default
for p in probes probes-rt; do frame box box 1600x900 $p-1 --gbuffer visibility --preset $p; done
frame box box 1600x900 default
frame toycar toycar 640x360 default
frame toycar toycar 640x360 rt4-16 --preset rt-4 --frames 16
frame lamp lamp 640x360 default
bench() { local file=$1 tag=$2; shift 2; echo "== bench $file $tag $*" >> $L; timeout 60 $B/kiln-play $W/$file.kiln --headless --size 1600x900 --bench --frames 100 "$@" 2>&1 | grep -B30 "^total" | grep -v "^$" >> $L; }
for r in 1 2; do
  for p in probes probes-rt; do bench pica $p --gbuffer visibility --preset $p; done
  bench picad probes-rt --gbuffer visibility --preset probes-rt
  bench toycar default
done
echo done >> $L
