#!/bin/bash
# Cold and warm first frames after building each pass's pipelines on a thread of its own.
set -u
cd "$(dirname "$0")"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $OUT/gpu.txt
R=/tmp/runs2; mkdir -p $R
./kiln compile pica_pica/scene.gltf --config ../tests/scenes/pica_pica.toml -o pica.kiln > $OUT/compile.txt 2>&1
P="./kiln-play pica.kiln --bench --json --size 1600x900 --frames 20"
RT="--shadows rt --ao rt --reflections rt --gi rt"
cold() { n=$1; shift; __GL_SHADER_DISK_CACHE=0 $P --no-pipeline-cache "$@" > $R/$n.json 2> $R/$n.err; }
warm() { n=$1; shift; $P "$@" > $R/$n.json 2> $R/$n.err; }
for i in 1 2 3; do cold cold-default-$i; cold cold-rt-progressive-$i $RT; cold cold-rt-complete-$i $RT --no-progressive-pipelines; done
warm fill-rt $RT; warm fill-default
for i in 1 2 3; do warm warm-default-$i; warm warm-rt-progressive-$i $RT; warm warm-rt-complete-$i $RT --no-progressive-pipelines; done
tar -C /tmp -cf $OUT/runs2.tar runs2
grep -h "first_frame_since_start_ms\|\"pipelines_ms\"" $R/cold-default-1.json $R/warm-default-1.json
