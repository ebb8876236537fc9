#!/bin/bash
# Raster vs visibility G-buffer: first frame since start and steady frame, default technique set.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w18; mkdir -p $W
L=$OUT/log18.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/ToyCar.gltf --environment studio
comp lamp $S/lamp/LightsPunctualLamp.gltf --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
$B/kiln demo -o $W/demo.kiln -q >> $L 2>&1
for r in 1 2 3; do
  for f in pica toycar lamp demo; do
    for g in raster visibility; do
      echo "== $f $g round $r" >> $L
      timeout 60 $B/kiln-play $W/$f.kiln --headless --size 1600x900 --bench --frames 100 --gbuffer $g --json > $W/b.json 2>$W/err.txt || tail -2 $W/err.txt >> $L
      python3 -c "
import json,sys
d=json.load(open('$W/b.json'))
keys=['first_frame_since_start_ms','full_ready_since_start_ms','full_frame_since_start_ms','resident_since_start_ms']
out={k:round(d['load'].get(k,0),1) for k in keys}
tot=[p for p in d.get('passes',[]) if p.get('pass')=='total']
out['total_median']=round(tot[0].get('median_ms'),3) if tot else None; out['gbuf']=[(p['pass'],round(p['median_ms'],3)) for p in d['passes'] if p['pass'] in ('gbuffer','resolve')]
print(out)" >> $L 2>&1 || head -c 600 $W/b.json >> $L
    done
  done
done
echo done >> $L
