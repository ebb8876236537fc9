#!/bin/bash
# Probe bake regularisation (this session's kiln, --probe-regularize 0 = before), denser probes,
# probes + RT shadows; ToyCar --gi rt at 7 cm vs scaled x14 (unit scale).
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log5.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; local t0=$(date +%s.%N); $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; local rc=$?; echo "compile $name rc=$rc $(echo "$(date +%s.%N) - $t0" | bc) s $(stat -c %s $W/$name.kiln) B" >> $L; $B/kiln inspect $W/$name.kiln 2>&1 | grep "irradiance probes" >> $L; }
PICA="$S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none"
comp pica0 $PICA --probe-regularize 0
comp pica $PICA
comp pica1k $PICA --probe-rays 1024
comp picad $PICA --probe-spacing 2.5 --probe-budget 64 --probe-rays 1024
comp box0 $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml --shaft-variants none --probe-regularize 0
comp box $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml --shaft-variants none
comp toycar0 $S/toycar/ToyCar.gltf --environment studio --probe-regularize 0
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp toycar14 $S/toycar/ToyCar14.gltf --environment studio
comp lamp0 $S/lamp/LightsPunctualLamp.gltf --environment studio --probe-regularize 0
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
ref() { local name=$1 size=$2; echo "== reference $name $size" >> $L; timeout 150 $B/kiln-play $W/$name.kiln --headless --reference --spp 4096 --size $size -o $W/$name-ref.exr 2>&1 | tail -1 >> $L; }
ref toycar 640x360; ref lamp 640x360; ref pica 1600x900; ref box 1600x900
frame() { local ref=$1 file=$2 size=$3 tag=$4; shift 4; echo "== frame $file $tag $*" >> $L; timeout 90 $B/kiln-play $W/$file.kiln --headless --size $size "$@" -o $W/f.exr > $W/play.txt 2>&1 || tail -3 $W/play.txt >> $L; $B/kiln-bench --diff $W/$ref-ref.exr $W/f.exr 2>&1 | head -1 >> $L; }
for f in pica0 pica pica1k picad; do
  frame pica $f 1600x900 default
  frame pica $f 1600x900 rtshadows --shadows rt
done
frame pica picad 1600x900 rtshadows4 --shadows rt --frames 4
frame pica pica 1600x900 rtshadows-rtrefl --shadows rt --reflections rt
frame pica pica 1600x900 hybrid --preset hybrid
for f in box0 box; do frame box $f 1600x900 default; done
for f in toycar0 toycar; do frame toycar $f 640x360 default; frame toycar $f 640x360 rt4-16 --preset rt-4 --frames 16; done
for f in lamp0 lamp; do frame lamp $f 640x360 default; done
bench() { local file=$1 tag=$2; shift 2; echo "== bench $file $tag $*" >> $L; timeout 60 $B/kiln-play $W/$file.kiln --headless --size 1600x900 --bench --frames 100 "$@" 2>&1 | tail -25 >> $L; }
bench pica default
bench pica rtshadows --shadows rt
bench picad rtshadows --shadows rt
bench pica hybrid --preset hybrid
bench toycar gi-rt --gi rt
bench toycar14 gi-rt --gi rt
bench toycar gi-rt-again --gi rt
bench toycar14 gi-rt-again --gi rt
echo "== toycar reference speed" >> $L
for f in toycar toycar14; do timeout 60 $B/kiln-play $W/$f.kiln --headless --reference --spp 512 --size 640x360 -o $W/r.exr 2>&1 | tail -1 >> $L; done
echo done >> $L
