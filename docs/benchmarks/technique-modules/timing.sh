#!/bin/bash
# Interleaved GPU timing: baseline (ab93dd4) and new kiln-play, default and seed-001 frames, pica_pica 1600x900.
set -u
cd "$(dirname "$0")"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $OUT/gpu.txt 2>&1
for round in 1 2 3 4 5 6 7; do
  if [ $((round % 2)) -eq 1 ]; then order="base new"; else order="new base"; fi
  for bin in $order; do
    for set in default seed001; do
      case $set in default) flags="";; seed001) flags="--gbuffer visibility --shadows rt --ao rt --reflections rt";; esac
      ./$bin-kiln-play pica.kiln --bench --json --size 1600x900 --frames 100 --warmup 10 $flags > $OUT/tmp.json 2>>$OUT/err.txt
      python3 -c "import json,sys; d=json.load(open('$OUT/tmp.json')); t=[p for p in d['passes'] if p['pass']=='total'][0]; print('$round $bin $set', t['median_ms'], d['device'])" >> $OUT/timing.txt
    done
  done
done
cat $OUT/timing.txt
