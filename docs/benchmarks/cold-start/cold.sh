#!/bin/bash
# Issue 18 item 5: first frame with progressive pipelines, cold and warm, on the GPU machine.
# A cold run: no kiln pipeline cache (--no-pipeline-cache) and the NVIDIA shader disk cache off.
set -u
cd "$(dirname "$0")"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $OUT/gpu.txt
R=/tmp/runs; mkdir -p $R
/usr/bin/time -v ./kiln compile pica_pica/scene.gltf --config ../tests/scenes/pica_pica.toml -o pica.kiln > $OUT/compile.txt 2>&1 || ./kiln compile pica_pica/scene.gltf --config ../tests/scenes/pica_pica.toml -o pica.kiln > $OUT/compile.txt 2>&1
P="./kiln-play pica.kiln --bench --json --size 1600x900 --frames 20"
RT="--shadows rt --ao rt --reflections rt --gi rt"
cold() { n=$1; shift; __GL_SHADER_DISK_CACHE=0 $P --no-pipeline-cache "$@" > $R/$n.json 2> $R/$n.err; }
warm() { n=$1; shift; $P "$@" > $R/$n.json 2> $R/$n.err; }
for i in 1 2 3; do cold cold-rt-progressive-$i $RT; cold cold-rt-complete-$i $RT --no-progressive-pipelines; cold cold-default-$i; done
warm fill-rt $RT; warm fill-default
for i in 1 2 3; do warm warm-rt-progressive-$i $RT; warm warm-rt-complete-$i $RT --no-progressive-pipelines; warm warm-default-$i; done
tar -C /tmp -cf $OUT/runs.tar runs
grep -h "first_frame_since_start_ms\|full_frame_since_start_ms" $R/cold-rt-progressive-1.json $R/warm-default-1.json
tail -3 $R/cold-rt-progressive-1.err
