#!/bin/bash
# The see-through layer: ToyCar, lamp, pica frames against references; timing new vs old binary.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w9; mkdir -p $W
L=$OUT/log9.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; local t0=$(date +%s%N); $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$? $(( ($(date +%s%N) - t0) / 1000000 )) ms $(stat -c %s $W/$name.kiln) B" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
ref() { local name=$1 size=$2; echo "== reference $name $size" >> $L; timeout 150 $B/kiln-play $W/$name.kiln --headless --reference --spp 4096 --size $size -o $W/$name-ref.exr 2>&1 | tail -1 >> $L; }
ref toycar 640x360; ref lamp 640x360
frame() { local bin=$1 ref=$2 file=$3 size=$4 tag=$5; shift 5; echo "== frame $bin $file $tag $*" >> $L; timeout 120 $B/$bin $W/$file.kiln --headless --size $size "$@" -o $W/$file-$bin-$tag.exr > $W/play.txt 2>&1 || tail -3 $W/play.txt >> $L; $B/kiln-bench --diff $W/$ref-ref.exr $W/$file-$bin-$tag.exr 2>&1 | head -1 >> $L; }
for bin in kiln-play kiln-play-old; do
  frame $bin toycar toycar 640x360 default
  frame $bin toycar toycar 640x360 rt4-16 --preset rt-4 --frames 16
  frame $bin lamp lamp 640x360 default
  frame $bin lamp lamp 640x360 rt4-16 --preset rt-4 --frames 16
done
cp $W/toycar-ref.exr $W/lamp-ref.exr $W/*-kiln-play-default.exr $W/*-kiln-play-old-default.exr $OUT/ 2>/dev/null
bench() { local bin=$1 file=$2 tag=$3; shift 3; echo "== bench $bin $file $tag $*" >> $L; timeout 60 $B/$bin $W/$file.kiln --headless --size 1600x900 --bench --frames 100 "$@" 2>&1 | grep -B40 "^total" | grep -v "^$" >> $L; }
for r in 1 2; do
  for bin in kiln-play kiln-play-old; do
    bench $bin toycar default
    bench $bin lamp default
    bench $bin pica probes-rt --gbuffer visibility --preset probes-rt
  done
done
ref pica 1600x900
for bin in kiln-play kiln-play-old; do frame $bin pica pica 1600x900 probes-rt --gbuffer visibility --preset probes-rt; done
echo done >> $L
