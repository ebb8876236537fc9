#!/bin/bash
# ToyCar's default frame: where its error is (images back), and what its emitters' direct light costs and gives.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w; mkdir -p $W
L=$OUT/log7.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; [ -f $W/$name.kiln ] && { echo "kept $name.kiln" >> $L; return; }; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
ref() { local name=$1 size=$2; [ -f $W/$name-ref.exr ] && { echo "kept $name-ref.exr" >> $L; return; }; echo "== reference $name $size" >> $L; timeout 150 $B/kiln-play $W/$name.kiln --headless --reference --spp 4096 --size $size -o $W/$name-ref.exr 2>&1 | tail -1 >> $L; }
ref toycar 640x360; ref lamp 640x360
cp $W/toycar-ref.exr $OUT/
frame() { local ref=$1 file=$2 tag=$3; shift 3; echo "== frame $file $tag $*" >> $L; timeout 90 $B/kiln-play $W/$file.kiln --headless --size 640x360 "$@" -o $W/$file-$tag.exr > $W/play.txt 2>&1 || tail -3 $W/play.txt >> $L; $B/kiln-bench --diff $W/$ref-ref.exr $W/$file-$tag.exr 2>&1 | head -1 >> $L; }
frame toycar toycar default
frame toycar toycar nodirect --direct none
frame toycar toycar probes-rt --preset probes-rt
frame toycar toycar vis --gbuffer visibility
frame toycar toycar rt4 --preset rt-4 --frames 16
frame lamp lamp default
frame lamp lamp nodirect --direct none
cp $W/toycar-default.exr $W/toycar-nodirect.exr $W/toycar-rt4.exr $OUT/
bench() { local file=$1 tag=$2; shift 2; echo "== bench $file $tag $*" >> $L; timeout 60 $B/kiln-play $W/$file.kiln --headless --size 1600x900 --bench --frames 100 "$@" 2>&1 | grep -B30 "^total" | grep -v "^$" >> $L; }
bench toycar default
bench toycar nodirect --direct none
bench toycar vis --gbuffer visibility
bench toycar vis-nodirect --gbuffer visibility --direct none
echo done >> $L
