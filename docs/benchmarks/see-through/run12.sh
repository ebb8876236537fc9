#!/bin/bash
# After 1,024 probe paths for glossy scenes and the see-through layer: pica presets (the built-in
# budget table), ToyCar, lamp, McGuire box default frames.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w12; mkdir -p $W
L=$OUT/log12.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; local t0=$(date +%s%N); $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$? $(( ($(date +%s%N) - t0) / 1000000 )) ms" >> $L; }
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
comp box $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml --shaft-variants none
$B/kiln plan $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml 2>&1 | grep " probes " >> $L
ref() { local name=$1 size=$2; echo "== reference $name $size" >> $L; timeout 150 $B/kiln-play $W/$name.kiln --headless --reference --spp 4096 --size $size -o $W/$name-ref.exr 2>&1 | tail -1 >> $L; }
ref pica 1600x900; ref toycar 640x360; ref lamp 640x360; ref box 1600x900
frame() { local ref=$1 file=$2 size=$3 tag=$4; shift 4; echo "== frame $file $tag $*" >> $L; timeout 120 $B/kiln-play $W/$file.kiln --headless --size $size "$@" -o $W/f.exr > $W/play.txt 2>&1 || tail -3 $W/play.txt >> $L; $B/kiln-bench --diff $W/$ref-ref.exr $W/f.exr 2>&1 | head -1 >> $L; }
frame pica pica 1600x900 default
for p in probes probes-rt baked baked-taa hybrid rt rt-taa rt-2 rt-4 rt-4-taa rt-8; do frame pica pica 1600x900 $p --gbuffer visibility --preset $p; done
frame toycar toycar 640x360 default
frame lamp lamp 640x360 default
frame box box 1600x900 default
bench() { local file=$1 tag=$2; shift 2; echo "== bench $file $tag $*" >> $L; timeout 60 $B/kiln-play $W/$file.kiln --headless --size 1600x900 --bench --frames 100 "$@" 2>&1 | grep "^total" >> $L; }
for r in 1 2; do
  for p in probes probes-rt baked baked-taa hybrid rt rt-taa rt-2 rt-4 rt-4-taa rt-8; do bench pica $p --gbuffer visibility --preset $p; done
  bench pica default
  bench toycar default
done
echo done >> $L
