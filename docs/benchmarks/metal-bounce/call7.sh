#!/bin/bash
# Session call 7: the metal bounce on two Khronos models (environment studio): probes-rt-refl at
# 1 and 16 frames with the bounce off and at its default, 1600x900, 2048-spp references.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w7; mkdir -p $W/x
L=$OUT/log7.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
SZ=1600x900
for n in toycar lamp; do
  case $n in toycar) src=$S/toycar/glTF/ToyCar.gltf;; lamp) src=$S/lamp/glTF/LightsPunctualLamp.gltf;; esac
  timeout 200 $B/kiln compile $src --environment studio -o $W/$n.kiln -q > $W/c-$n.txt 2>&1; echo "compile $n rc=$?" >> $L
  timeout 90 $B/kiln-play $W/$n.kiln --reference --spp 2048 --size $SZ -o $W/x/$n-ref.exr 2>&1 | tail -1 >> $L
  for mb in 0 0.6; do for fr in 1 16; do
    echo "== $n bounce $mb frames $fr" >> $L
    timeout 60 $B/kiln-play $W/$n.kiln --headless --size $SZ --preset probes-rt-refl --reflection-metal-bounce $mb --frames $fr -o $W/x/$n-$mb-$fr.exr > /dev/null 2>>$W/err.txt || echo FAILED >> $L
    $B/kiln-bench --diff $W/x/$n-ref.exr $W/x/$n-$mb-$fr.exr -o $W/d 2>&1 | head -1 >> $L
  done; done
  for mb in 0 0.6; do echo "== bench $n bounce $mb" >> $L; timeout 60 $B/kiln-play $W/$n.kiln --headless --size $SZ --bench --frames 200 --preset probes-rt-refl --reflection-metal-bounce $mb 2>&1 | grep -E "^(reflections|total)" >> $L; done
done
echo done >> $L
