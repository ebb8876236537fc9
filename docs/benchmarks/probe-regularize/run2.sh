#!/bin/bash
# probes-rt preset (visibility G-buffer) vs probes; default and dense probe bakes; pica and the box.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log6.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; [ -f $W/$name.kiln ] && { echo "kept $name.kiln" >> $L; return; }; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
PICA="$S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none"
comp pica $PICA
comp picad $PICA --probe-spacing 2.5 --probe-budget 64 --probe-rays 1024
comp box $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml --shaft-variants none
ref() { local name=$1 size=$2; [ -f $W/$name-ref.exr ] && { echo "kept $name-ref.exr" >> $L; return; }; echo "== reference $name $size" >> $L; timeout 150 $B/kiln-play $W/$name.kiln --headless --reference --spp 4096 --size $size -o $W/$name-ref.exr 2>&1 | tail -1 >> $L; }
ref pica 1600x900; ref box 1600x900
frame() { local ref=$1 file=$2 tag=$3; shift 3; echo "== frame $file $tag $*" >> $L; timeout 90 $B/kiln-play $W/$file.kiln --headless --size 1600x900 "$@" -o $W/f.exr > $W/play.txt 2>&1 || tail -3 $W/play.txt >> $L; $B/kiln-bench --diff $W/$ref-ref.exr $W/f.exr 2>&1 | head -1 >> $L; }
for f in pica picad; do for p in probes probes-rt; do for n in 1 4; do frame pica $f $p-$n --gbuffer visibility --preset $p --frames $n; done; done; done
for p in probes probes-rt; do for n in 1 4; do frame box box $p-$n --gbuffer visibility --preset $p --frames $n; done; done
bench() { local file=$1 tag=$2; shift 2; echo "== bench $file $tag $*" >> $L; timeout 60 $B/kiln-play $W/$file.kiln --headless --size 1600x900 --bench --frames 100 "$@" 2>&1 | grep -B30 "^total" | grep -v "^$" >> $L; }
for r in 1 2; do
  for p in probes probes-rt hybrid; do bench pica $p --gbuffer visibility --preset $p; done
  bench picad probes-rt --gbuffer visibility --preset probes-rt
  for p in probes probes-rt; do bench box $p --gbuffer visibility --preset $p; done
done
echo done >> $L
