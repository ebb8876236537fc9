#!/bin/bash
# run.sh PLAYER OUTDIR: renders every set of sets.txt at 48x36, 3 frames, headless PNG.
player=$1; out=$2; mkdir -p $out
while IFS='|' read -r scene name flags; do
  $player $(dirname "$0")/$scene.kiln --headless --size 48x36 --frames 3 --no-pipeline-cache $flags -o $out/$name.png > $out/$name.log 2>&1 || echo "FAIL $name" >> $out/fail.txt
done < "$(dirname "$0")/sets.txt"
